#include "motion/bvh.hpp"

#include <filesystem>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "motion/pose_sequence.hpp"
#include "support/shared_data.hpp"

namespace mocap::motion {
namespace {

// Two joints with different channel orders, an End Site, tabs, CRLF and exponent notation.
const char* kSmall =
    "HIERARCHY\r\nROOT Hips\r\n{\r\n\tOFFSET 0 0 0\r\n\tCHANNELS 6 Xposition Yposition Zposition "
    "Zrotation "
    "Yrotation Xrotation\r\n\tJOINT Chest\r\n\t{\r\n\t\tOFFSET 0 1.0e1 0\r\n\t\tCHANNELS 3 "
    "Zrotation Xrotation "
    "Yrotation\r\n\t\tEnd Site\r\n\t\t{\r\n\t\t\tOFFSET 0 5 "
    "0\r\n\t\t}\r\n\t}\r\n}\r\nMOTION\r\nFrames:\t2\r\n"
    "Frame Time: .0333333\r\n1 2 3 10 20 30 0 90 0\r\n-1 +2 3.5e-1 0 0 0 45 0 0\r\n";

TEST(Bvh, ParsesHierarchyAndMotion) {
  const Clip c = parse_bvh(kSmall, "small.bvh");
  ASSERT_EQ(c.skeleton.joint_count(), 3);
  EXPECT_EQ(c.skeleton.joints[1].name, "Chest");
  EXPECT_EQ(c.skeleton.joints[1].offset.y, 10.0f);
  EXPECT_TRUE(c.skeleton.joints[2].end_site);
  EXPECT_EQ(c.skeleton.joints[2].parent, 1);
  EXPECT_EQ(c.skeleton.channel_count, 9);
  EXPECT_EQ(c.frame_count, 2);
  EXPECT_NEAR(c.fps(), 30.0, 1e-3);
  EXPECT_FLOAT_EQ(c.frame(1)[2], 0.35f);
  EXPECT_FLOAT_EQ(c.frame(1)[1], 2.0f);
}

TEST(Bvh, ForwardKinematicsFollowsChannelOrder) {
  const PoseSequence p = to_poses(parse_bvh(kSmall, "small.bvh"));
  GlobalPose g;
  forward_kinematics(p, 1, g);
  // Frame 1: root at (-1, 2, 0.35) unrotated; Chest Zrotation 45 turns the End Site's +Y offset
  // of 5 towards -X: (-5 sin45, 5 cos45, 0) above the chest at (-1, 12, 0.35).
  EXPECT_NEAR(g.position[1].y, 12.0f, 1e-5);
  EXPECT_NEAR(g.position[2].x, -1.0f - 5.0f * std::sqrt(0.5f), 1e-5);
  EXPECT_NEAR(g.position[2].y, 12.0f + 5.0f * std::sqrt(0.5f), 1e-5);
}

TEST(Bvh, WriteReadRoundTripIsExact) {
  const Clip a = parse_bvh(kSmall, "small.bvh");
  std::ostringstream out;
  write_bvh(a, out);
  const Clip b = parse_bvh(out.str(), "written.bvh");
  ASSERT_EQ(b.skeleton.joint_count(), a.skeleton.joint_count());
  EXPECT_EQ(b.values, a.values);
  EXPECT_EQ(b.frame_count, a.frame_count);
  EXPECT_EQ(b.skeleton.joints[2].offset, a.skeleton.joints[2].offset);
}

TEST(Bvh, EulerConversionReproducesTheMotion) {
  const PoseSequence a = to_poses(parse_bvh(kSmall, "small.bvh"));
  const PoseSequence b = to_poses(to_clip(a));
  GlobalPose ga, gb;
  for (int f = 0; f < a.frame_count; ++f) {
    forward_kinematics(a, f, ga);
    forward_kinematics(b, f, gb);
    for (int j = 0; j < a.joint_count(); ++j)
      EXPECT_NEAR(glm::distance(ga.position[j], gb.position[j]), 0.0f, 1e-4);
  }
}

// A streaming writer killed between appending a frame line and raising the count leaves one
// line, whole or cut short, after the declared frames: the frames declared are read.
TEST(Bvh, OneUnfinishedFrameLineAfterTheDeclaredFramesIsIgnored) {
  const std::string good = kSmall;
  for (const char* tail : {"7 7 7 7 7 7 7 7 7\n", "7 7 7 7 7 7 7 7 7", "7 7 -", "  \r\n"}) {
    const Clip c = parse_bvh(good + tail, "killed.bvh");
    EXPECT_EQ(c.frame_count, 2) << tail;
    EXPECT_EQ(c.values, parse_bvh(good, "small.bvh").values) << tail;
  }
}

void expect_error(const std::string& text, const std::string& fragment) {
  try {
    parse_bvh(text, "bad.bvh");
    ADD_FAILURE() << "no error for: " << fragment;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.bvh:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(Bvh, MalformedInputNamesFileAndLine) {
  const std::string good = kSmall;
  expect_error("", "unexpected end of file");
  expect_error("HIERARCHY\nROOT Hips\n{\nOFFSET 0 0\n",
               "bad.bvh:5: unexpected end of file, expected OFFSET z");
  expect_error("HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 x\n",
               "bad.bvh:4: expected a number for OFFSET z");
  expect_error(good.substr(0, good.size() - 12), "truncated");
  expect_error(good + "7 7 7\n8 8 8\n", "more values");
  expect_error(good + "1 2 3 4 5 6 7 8 9 10\n", "more values");
  expect_error("HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 1 Wrotation\n}\nMOTION\n",
               "bad.bvh:5: unknown channel");
  expect_error(
      "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: "
      "5000000\nFrame Time: 1\n1\n",
      "truncated");
  expect_error(
      "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: "
      "999999999\nFrame Time: 1\n1\n",
      "implausible frame count");
  expect_error("HIERARCHY\nROOT a\n{\nOFFSET nan 0 0\n", "expected a number");
}

TEST(Bvh, RandomBytesNeverCrash) {
  std::mt19937 rng(7);
  const std::string good = kSmall;
  for (int trial = 0; trial < 2000; ++trial) {
    std::string text = good;
    const int edits = 1 + static_cast<int>(rng() % 8);
    for (int e = 0; e < edits; ++e) text[rng() % text.size()] = static_cast<char>(rng() % 256);
    if (trial % 3 == 0) text.resize(rng() % text.size());
    try {
      parse_bvh(text, "fuzz.bvh");
    } catch (const InputError&) {
    }
  }
}

// Every file of the shared mocap collection parses, and its frame count matches its header.
TEST(Bvh, EverySharedMocapFileParses) {
  MOCAP_REQUIRE_SHARED("mocap");
  int files = 0;
  for (const auto& e :
       std::filesystem::recursive_directory_iterator(test::shared_data() / "mocap")) {
    if (e.path().extension() != ".bvh") continue;
    const Clip c = read_bvh(e.path().string());
    EXPECT_GT(c.frame_count, 0) << e.path();
    EXPECT_EQ(c.values.size(), static_cast<size_t>(c.frame_count) * c.skeleton.channel_count)
        << e.path();
    ++files;
  }
  EXPECT_GE(files, 60);
}

// Round trip of a real file: every channel value reads back identical.
TEST(Bvh, RealFileRoundTrip) {
  MOCAP_REQUIRE_SHARED("mocap/cmu_daz/07_01.bvh");
  const Clip a = read_bvh((test::shared_data() / "mocap/cmu_daz/07_01.bvh").string());
  test::TempDir dir;
  write_bvh(a, dir.file("07_01.bvh"));
  const Clip b = read_bvh(dir.file("07_01.bvh"));
  EXPECT_EQ(a.values, b.values);
  EXPECT_EQ(a.skeleton.joint_count(), b.skeleton.joint_count());
}

TEST(Bvh, MissingFileIsAClearError) { EXPECT_THROW(read_bvh("/nonexistent/x.bvh"), InputError); }

}  // namespace
}  // namespace mocap::motion
