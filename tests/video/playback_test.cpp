// video::Playback: a looped folder goes on stamping where the previous pass ended; a paced folder
// is stamped with the times its frames were due, passes over the frames a slow reader is late for,
// and a wait cut short (a stop) is not taken for the end; a frame offset shifts indices and stamps;
// a replay rate paces a file or folder at a camera's rate instead of its own.

#include "video/playback.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <ctime>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "support/files.hpp"

namespace mocap::video {
namespace {

constexpr std::int64_t kMs = 1'000'000;

// A folder of `count` small numbered images.
std::string image_folder(const test::TempDir& dir, int count) {
  for (int n = 0; n < count; ++n)
    cv::imwrite(dir.file("frame_" + std::to_string(n) + ".png"),
                cv::Mat(8, 8, CV_8UC3, cv::Scalar(n, 0, 0)));
  return dir.path().string();
}

SourceOptions at_fps(double fps) {
  SourceOptions options;
  options.folder_fps = fps;
  return options;
}

std::int64_t now_ns() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

bool sleep_until(std::int64_t due_ns) {
  std::this_thread::sleep_for(std::chrono::nanoseconds(due_ns - now_ns()));
  return true;
}

TEST(Playback, ALoopedFolderStampsEachPassAfterThePreviousOne) {
  const test::TempDir dir;
  Playback playback(image_folder(dir, 3), at_fps(10.0), {.live = false, .loop = true});
  EXPECT_FALSE(playback.live());
  std::vector<std::int64_t> stamps;
  for (int i = 0; i < 7; ++i) {
    const auto frame = playback.next(sleep_until);
    ASSERT_TRUE(frame);
    stamps.push_back(frame->stamp_ns);
  }
  for (std::size_t i = 0; i < stamps.size(); ++i)
    EXPECT_EQ(stamps[i], static_cast<std::int64_t>(i) * 100 * kMs) << "frame " << i;
  EXPECT_EQ(playback.passes_started_again(), 2u);
  EXPECT_EQ(playback.describe_losses(),
            "0 skipped (late), 0 corrupt frames skipped, started again 2 times");
}

TEST(Playback, AFrameOffsetShiftsIndicesAndStampsAlike) {
  const test::TempDir dir;
  Playback playback(image_folder(dir, 3), at_fps(10.0), {.live = false, .frame_offset = -2});
  for (std::int64_t i = 0; i < 3; ++i) {
    const auto frame = playback.next(sleep_until);
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->frame.index, i - 2);
    EXPECT_EQ(frame->stamp_ns, (i - 2) * 100 * kMs) << "frame " << i;
  }
  EXPECT_FALSE(playback.next(sleep_until));
  EXPECT_EQ(playback.describe_losses(), "0 skipped (late), 0 corrupt frames skipped");
}

TEST(Playback, AFolderEndsAfterOnePassWithoutLoop) {
  const test::TempDir dir;
  Playback playback(image_folder(dir, 3), at_fps(10.0), {});
  EXPECT_FALSE(playback.live());  // unset: offline for a folder
  int frames = 0;
  while (playback.next(sleep_until)) ++frames;
  EXPECT_EQ(frames, 3);
  EXPECT_FALSE(playback.stopped());
  EXPECT_NE(playback.describe().find("3 frames, offline"), std::string::npos)
      << playback.describe();
}

TEST(Playback, APacedFolderIsStampedWhenItsFramesAreDue) {
  const test::TempDir dir;
  // 10 fps: a frame is passed over only when the reader is 100 ms late (a loaded machine is not).
  Playback playback(image_folder(dir, 4), at_fps(10.0), {.live = true, .loop = false});
  std::vector<std::int64_t> stamps;
  while (auto frame = playback.next(sleep_until)) {
    EXPECT_GE(now_ns(), frame->stamp_ns);  // not handed out before it was due
    stamps.push_back(frame->stamp_ns);
  }
  ASSERT_EQ(stamps.size(), 4u);
  for (std::size_t i = 1; i < stamps.size(); ++i) EXPECT_EQ(stamps[i] - stamps[i - 1], 100 * kMs);
  EXPECT_EQ(playback.late_frames_passed_over(), 0u);
}

// replay_fps: a 10 fps folder replayed as a 25 fps camera is due every 40 ms, and says so.
TEST(Playback, AReplayRatePacesAFolderInsteadOfItsOwnRate) {
  const test::TempDir dir;
  Playback playback(image_folder(dir, 4), at_fps(10.0), {.live = true, .replay_fps = 25.0});
  EXPECT_NE(playback.describe().find("replayed at 25 fps"), std::string::npos)
      << playback.describe();
  std::vector<std::int64_t> stamps;
  while (auto frame = playback.next(sleep_until)) stamps.push_back(frame->stamp_ns);
  ASSERT_EQ(stamps.size(), 4u);
  for (std::size_t i = 1; i < stamps.size(); ++i) EXPECT_EQ(stamps[i] - stamps[i - 1], 40 * kMs);
}

TEST(Playback, APacedFolderPassesOverTheFramesASlowReaderIsLateFor) {
  const test::TempDir dir;
  Playback playback(image_folder(dir, 12), at_fps(100.0), {.live = true, .loop = false});
  int frames = 0;
  while (auto frame = playback.next(sleep_until)) {
    ++frames;
    std::this_thread::sleep_for(std::chrono::milliseconds(35));  // 3.5 frame periods
  }
  EXPECT_GT(playback.late_frames_passed_over(), 0u);
  EXPECT_EQ(static_cast<std::uint64_t>(frames) + playback.late_frames_passed_over(), 12u);
}

TEST(Playback, AWaitCutShortIsAStopNotTheEnd) {
  const test::TempDir dir;
  Playback playback(image_folder(dir, 4), at_fps(10.0), {.live = true, .loop = true});
  ASSERT_TRUE(playback.next(sleep_until));  // the first frame is due at once
  EXPECT_FALSE(playback.next([](std::int64_t) { return false; }));
  EXPECT_TRUE(playback.stopped());
  EXPECT_EQ(playback.passes_started_again(), 0u);
}

}  // namespace
}  // namespace mocap::video
