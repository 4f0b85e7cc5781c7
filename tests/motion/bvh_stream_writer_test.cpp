// The streaming BVH writer: the file on disk reads back after every frame, also in the states a
// kill can leave between two system calls, and also after a real SIGKILL of a writing process.

#include "motion/bvh_stream_writer.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "motion/bvh.hpp"
#include "support/errors.hpp"
#include "support/shared_data.hpp"

namespace mocap::motion {
namespace {

using test::error_of;

// A root with position channels, a chain of joints in two channel orders and an End Site:
// `joints` joints, 3 + 3 * joints channels.
Skeleton chain(int joints) {
  Skeleton s;
  for (int j = 0; j < joints; ++j) {
    SkeletonJoint joint;
    char name[16];
    std::snprintf(name, sizeof name, "J%d", j);  // ("J" + to_string trips GCC 12's -Wrestrict)
    joint.name = name;
    joint.parent = j - 1;
    joint.offset = glm::vec3(0.0f, j == 0 ? 0.0f : 10.0f, 0.5f);
    if (j == 0) joint.channels = {Channel::Xposition, Channel::Yposition, Channel::Zposition};
    const bool zyx = j % 2 == 0;
    for (Channel c : zyx ? std::vector{Channel::Zrotation, Channel::Yrotation, Channel::Xrotation}
                         : std::vector{Channel::Xrotation, Channel::Zrotation, Channel::Yrotation})
      joint.channels.push_back(c);
    s.joints.push_back(joint);
  }
  SkeletonJoint end;
  end.name = s.joints.back().name + "_End";
  end.parent = joints - 1;
  end.end_site = true;
  end.offset = glm::vec3(0.0f, 5.0f, 0.0f);
  s.joints.push_back(end);
  s.assign_channel_slots();
  return s;
}

// Frame f's values: distinct, with long and short float texts, so lines vary in length.
std::vector<float> frame_values(const Skeleton& s, int f) {
  std::vector<float> v(static_cast<size_t>(s.channel_count));
  for (size_t c = 0; c < v.size(); ++c)
    v[c] = static_cast<float>(f) * 1.25f + static_cast<float>(c) / 7.0f - 90.0f;
  return v;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void expect_frames(const Clip& clip, const Skeleton& s, int frames) {
  ASSERT_EQ(clip.frame_count, frames) << clip.source;
  for (int f = 0; f < frames; ++f) {
    const std::vector<float> expected = frame_values(s, f);
    ASSERT_EQ(std::vector<float>(clip.frame(f), clip.frame(f) + s.channel_count), expected)
        << clip.source << " frame " << f;
  }
}

TEST(BvhStreamWriter, FileReadsBackExactlyAfterEveryFrame) {
  test::TempDir dir;
  const Skeleton s = chain(5);
  {
    BvhStreamWriter empty(dir.file("empty.bvh"), s, 1.0 / 30.0);
    EXPECT_FALSE(std::filesystem::exists(dir.file("empty.bvh"))) << "a new file before a frame";
    empty.close();  // closed without a frame: the hierarchy and a count of 0
    EXPECT_EQ(read_bvh(dir.file("empty.bvh")).frame_count, 0);
  }
  BvhStreamWriter writer(dir.file("a.bvh"), s, 1.0 / 30.0);
  for (int f = 0; f < 40; ++f) {
    writer.append(frame_values(s, f));
    const Clip clip = read_bvh(dir.file("a.bvh"));
    expect_frames(clip, s, f + 1);
    EXPECT_NEAR(clip.fps(), 30.0, 1e-4);  // the reader keeps the frame time as a float
    ASSERT_EQ(clip.skeleton.joint_count(), s.joint_count());
  }
  writer.close();
  EXPECT_NE(read_bytes(dir.file("a.bvh")).find("Frames: 0000000040\n"), std::string::npos);
}

// Every state a kill can leave: k frames counted, then nothing, padding spaces, or any prefix of
// the next frame's line. The reader must give the k frames each time.
TEST(BvhStreamWriter, EveryStateAKillCanLeaveReadsBack) {
  test::TempDir dir;
  const Skeleton s = chain(4);
  BvhStreamWriter(dir.file("header.bvh"), s, 0.04).close();  // what b.bvh holds before a frame
  BvhStreamWriter writer(dir.file("b.bvh"), s, 0.04);
  std::vector<std::string> states{read_bytes(dir.file("header.bvh"))};
  for (int f = 0; f < 12; ++f) {
    writer.append(frame_values(s, f));
    states.push_back(read_bytes(dir.file("b.bvh")));
  }
  for (int k = 0; k + 1 < static_cast<int>(states.size()); ++k) {
    const std::string& counted = states[static_cast<size_t>(k)];
    // The next state's tail is what the next append wrote (padding and line), with the count of
    // this state still in front of it.
    const std::string next_tail = states[static_cast<size_t>(k) + 1].substr(counted.size());
    for (size_t cut = 0; cut <= next_tail.size(); ++cut) {
      const Clip clip = parse_bvh(counted + next_tail.substr(0, cut), "cut.bvh");
      expect_frames(clip, s, k);
    }
  }
}

// A write killed by a signal can stop between two pages, never inside one: no frame line and
// not the count cross a page boundary (lines up to a page long).
TEST(BvhStreamWriter, NoFrameLineAndNotTheCountCrossAPageBoundary) {
  test::TempDir dir;
  const Skeleton s = chain(40);  // about 1 KB per line: many lines would cross a boundary
  BvhStreamWriter writer(dir.file("c.bvh"), s, 0.01);
  for (int f = 0; f < 60; ++f) writer.append(frame_values(s, f));
  writer.close();
  const std::string text = read_bytes(dir.file("c.bvh"));
  const size_t count_at = text.find("Frames: ") + 8;
  EXPECT_EQ(count_at / 4096, (count_at + 9) / 4096);
  size_t start = text.find('\n', text.find("Frame Time:")) + 1;
  int lines = 0;
  while (start < text.size()) {
    const size_t first = text.find_first_not_of(' ', start);
    const size_t end = text.find('\n', first);
    ASSERT_NE(end, std::string::npos);
    EXPECT_EQ(first / 4096, end / 4096) << "line " << lines << " at " << first;
    ++lines;
    start = end + 1;
  }
  EXPECT_EQ(lines, 60);
  expect_frames(read_bvh(dir.file("c.bvh")), s, 60);
}

// A real process writing frames in a loop, killed with SIGKILL at different moments: the file
// always reads back, with every frame it declares intact.
TEST(BvhStreamWriter, FileOfAProcessKilledMidWriteReadsBack) {
  test::TempDir dir;
  const Skeleton s = chain(31);
  for (int round = 0; round < 12; ++round) {
    const std::string path = dir.file("killed" + std::to_string(round) + ".bvh");
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      // Child: write until killed; at most a bounded number of frames so it can never run away.
      try {
        BvhStreamWriter writer(path, s, 1.0 / 120.0);
        for (int f = 0; f < 2'000'000; ++f) writer.append(frame_values(s, f));
      } catch (...) {
        _exit(3);
      }
      _exit(2);
    }
    // The first rounds kill at any moment from the start, also before the file exists; the later
    // ones count from the file's appearance, so that a slow start (a loaded machine, a sanitizer
    // build) still leaves time for frames.
    if (round > 4) {
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
      while (!std::filesystem::exists(path) && std::chrono::steady_clock::now() < give_up)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(15 + 9 * round));
    ASSERT_EQ(kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the child ended by itself, status " << status;
    if (!std::filesystem::exists(path)) continue;  // killed before it created the file
    const Clip clip = read_bvh(path);
    expect_frames(clip, s, clip.frame_count);
    std::cout << "[ note ] killed after " << 15 + 9 * round << " ms: " << clip.frame_count
              << " frames\n";
    if (round > 4) {
      EXPECT_GT(clip.frame_count, 0) << "round " << round;
    }
  }
}

// A process making many new files, killed while at it, leaves each of them whole or absent and no
// temporary file beside them (a new file is written unnamed and linked with its header).
TEST(BvhStreamWriter, AKillWhileCreatingFilesLeavesNoTemporaryFile) {
  test::TempDir dir;
  const Skeleton s = chain(31);
  for (int round = 0; round < 4; ++round) {
    const std::filesystem::path folder = dir.path() / std::to_string(round);
    std::filesystem::create_directories(folder);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      try {
        for (int k = 0; k < 100'000; ++k)  // bounded: it can never run away
          BvhStreamWriter((folder / ("p" + std::to_string(k) + ".bvh")).string(), s, 0.01);
      } catch (...) {
        _exit(3);
      }
      _exit(2);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20 + 13 * round));
    ASSERT_EQ(kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the child ended by itself, status " << status;
    for (const auto& e : std::filesystem::directory_iterator(folder)) {
      EXPECT_EQ(e.path().extension(), ".bvh") << e.path();
      EXPECT_EQ(read_bvh(e.path().string()).frame_count, 0) << e.path();
    }
  }
}

TEST(BvhStreamWriter, ErrorsNameTheFile) {
  test::TempDir dir;
  const Skeleton s = chain(2);
  // A folder that cannot be written (root writes anyway: then that part is skipped below).
  const std::filesystem::path locked = dir.path() / "locked";
  std::filesystem::create_directory(locked);
  chmod(locked.c_str(), 0555);
  const std::string in_locked = (locked / "x.bvh").string();
  if (access(locked.c_str(), W_OK) != 0) {
    const std::string e = error_of([&] { BvhStreamWriter(in_locked, s, 0.1); });
    EXPECT_NE(e.find(in_locked), std::string::npos) << e;
    EXPECT_NE(e.find("cannot create"), std::string::npos) << e;
  } else {
    std::cout << "[ note ] running as root: a read-only folder does not stop writes; the "
                 "not-a-folder and disk-full cases below still run\n";
  }
  chmod(locked.c_str(), 0755);
  // A path through a regular file.
  std::ofstream(dir.file("plain")) << "x";
  const std::string through_file = dir.file("plain") + "/x.bvh";
  std::string e = error_of([&] { BvhStreamWriter(through_file, s, 0.1); });
  EXPECT_NE(e.find(through_file), std::string::npos) << e;
  // A full disk: /dev/full takes the open and refuses every write with ENOSPC.
  if (access("/dev/full", W_OK) == 0) {
    e = error_of([&] { BvhStreamWriter("/dev/full", s, 0.1); });
    EXPECT_NE(e.find("/dev/full"), std::string::npos) << e;
    EXPECT_NE(e.find("No space"), std::string::npos) << e;
  }
  BvhStreamWriter writer(dir.file("ok.bvh"), s, 0.1);
  EXPECT_THROW(writer.append(std::vector<float>(3, 0.0f)), std::invalid_argument);
  std::vector<float> values = frame_values(s, 0);
  values[1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(writer.append(values), std::invalid_argument);
  EXPECT_EQ(writer.frame_count(), 0);
}

TEST(BvhStreamWriter, SuspendedFileResumesOnAppendAndRefusesOutsideChanges) {
  test::TempDir dir;
  const Skeleton s = chain(3);
  BvhStreamWriter writer(dir.file("d.bvh"), s, 0.1);
  writer.append(frame_values(s, 0));
  writer.suspend();
  EXPECT_FALSE(writer.is_open());
  EXPECT_TRUE(writer.is_suspended());
  writer.append(frame_values(s, 1));
  EXPECT_TRUE(writer.is_open());
  expect_frames(read_bvh(dir.file("d.bvh")), s, 2);
  writer.suspend();
  std::ofstream(dir.file("d.bvh"), std::ios::app) << "tampered\n";
  const std::string e = error_of([&] { writer.append(frame_values(s, 2)); });
  EXPECT_NE(e.find(dir.file("d.bvh")), std::string::npos) << e;
  EXPECT_NE(e.find("changed"), std::string::npos) << e;
}

TEST(BvhStreamWriter, MovedWriterKeepsWriting) {
  test::TempDir dir;
  const Skeleton s = chain(2);
  BvhStreamWriter a(dir.file("e.bvh"), s, 0.1);
  a.append(frame_values(s, 0));
  BvhStreamWriter b = std::move(a);
  b.append(frame_values(s, 1));
  b.close();
  b.close();  // idempotent
  expect_frames(read_bvh(dir.file("e.bvh")), s, 2);
}

}  // namespace
}  // namespace mocap::motion
