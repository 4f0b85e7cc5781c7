// Frame offsets of a calibrated rig's views (camera/frame_offsets.hpp): views of a virtual scene
// (a runner of a CMU *train* clip, 3 cameras of a ring, detector-like noise) cut to start at
// different frames come back with their offsets, to a fraction of a frame; nobody in view,
// cameras that do not match the views and people standing still are refused with the reason.

#include "camera/frame_offsets.hpp"

#include <gtest/gtest.h>

#include <iostream>
#include <map>

#include "camera/camera.hpp"
#include "camera/rig_file.hpp"
#include "eval/offset_scene.hpp"
#include "io/openpose_json.hpp"
#include "support/shared_data.hpp"

namespace mocap::camera {
namespace {

using Views = eval::ShiftedViews;

// `frames` frames per view of one runner (09_12, train) seen by a ring of 3 cameras, the scene
// read at `steps` x 30 frames/s: view v's frame i is scene step (i + starts[v]) * steps +
// phases[v]; 2D noise σ `noise` of the box height, 10 % of the joints dropped.
Views runner_views(const std::vector<int>& starts, const std::vector<int>& phases, int steps,
                   int frames, float noise) {
  static std::map<int, std::vector<eval::TruthSequence>> truth;  // per rate, read once
  if (!truth.contains(steps)) {
    const auto file = test::shared_data() / "mocap" / "cmu31" / "09_12.bvh";
    truth[steps] = eval::load_truth({file.string()}, 30.0 * steps);
  }
  eval::ScenePerson person;
  person.motion = &truth[steps].front();
  eval::SceneDegradation degradation;
  degradation.noise = noise;
  degradation.dropout = 0.10f;
  degradation.occlusion = false;
  return eval::shifted_views(person, eval::ring_rig(3, 5.0, 1.6, 0.5, {0.0, 1.0, 0.0}, {}), starts,
                             phases, steps, frames, degradation, 7);
}

TEST(FrameOffsets, ViewsThatStartLateOrEarlyAreFound) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/09_12.bvh");
  const Views s = runner_views({10, 17, 4}, {0, 0, 0}, 1, 150, 0.02f);
  const std::vector<ViewOffset> offsets = estimate_offsets(s.cameras, s.views, 0);
  ASSERT_EQ(offsets.size(), 3u);
  EXPECT_TRUE(offsets[0].found);
  EXPECT_EQ(offsets[0].frames, 0.0);
  for (std::size_t v = 1; v < 3; ++v) {
    ASSERT_TRUE(offsets[v].found) << offsets[v].problem;
    std::cout << "[ measured ] view " << v << ": " << offsets[v].frames << " frames (contrast "
              << offsets[v].contrast << ")\n";
  }
  EXPECT_NEAR(offsets[1].frames, 7.0, 0.75);  // σ 2 % leaves the minimum flat to a frame
  EXPECT_NEAR(offsets[2].frames, -6.0, 0.75);
}

TEST(FrameOffsets, FractionsOfAFrameAreSeen) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/09_12.bvh");
  // The scene at 120 frames/s, each view taking every 4th step: view 1 starts 2 steps (half a
  // frame) after view 0, view 2 three frames and a quarter. Noise σ 1 %.
  const Views s = runner_views({10, 10, 13}, {0, 2, 1}, 4, 150, 0.01f);
  const std::vector<ViewOffset> offsets = estimate_offsets(s.cameras, s.views, 0);
  ASSERT_TRUE(offsets[1].found) << offsets[1].problem;
  ASSERT_TRUE(offsets[2].found) << offsets[2].problem;
  std::cout << "[ measured ] " << offsets[1].frames << " for 0.5, " << offsets[2].frames
            << " for 3.25\n";
  EXPECT_NEAR(offsets[1].frames, 0.5, 0.4);  // closer to the truth than a whole frame's rounding
  EXPECT_NEAR(offsets[2].frames, 3.25, 0.4);
}

TEST(FrameOffsets, NobodyOrCamerasThatDoNotMatchTheViewsAreRefusedWithTheReason) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/09_12.bvh");
  const Views s = runner_views({10}, {0}, 1, 2, 0.0f);
  const BodySequence empty(50);
  const std::vector<BodySequence> nobody = {empty, empty, empty};
  const ViewOffset none = estimate_offsets(s.cameras, nobody, 0)[1];
  EXPECT_FALSE(none.found);
  EXPECT_NE(none.problem.find("no frames with people in both views"), std::string::npos)
      << none.problem;
  const std::vector<BodySequence> two = {empty, empty};
  EXPECT_NE(estimate_offsets(s.cameras, two, 0)[1].problem.find("3 cameras for 2 views"),
            std::string::npos);
}

// Pose2Sim's static trial: the participant stands still, so any offset fits as well.
TEST(FrameOffsets, PeopleStandingStillAreRefused) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/S00_P00_T00_StaticTrial/pose/cam01_json");
  const auto demo = test::shared_data() / "eval" / "pose2sim_demo";
  const Rig rig = read_rig(demo / "calibration" / "Calib_qualisys.toml");
  io::OpenPoseOptions json;
  json.body25 = io::Body25Choice::body25b;
  std::vector<BodySequence> views;
  for (const char* c : {"cam01", "cam02", "cam03", "cam04"}) {
    const auto folder = demo / "S00_P00_T00_StaticTrial" / "pose" / (std::string(c) + "_json");
    views.push_back(body_sequence(io::read_openpose_folder(folder, json).frames));
  }
  OffsetOptions options;
  options.max_offset_frames = 3;
  options.min_overlap_frames = 8;
  const std::vector<ViewOffset> offsets = estimate_offsets(rig.cameras, views, 0, options);
  for (std::size_t v = 1; v < 4; ++v) {
    EXPECT_FALSE(offsets[v].found) << v << ": " << offsets[v].frames;
    EXPECT_FALSE(offsets[v].problem.empty());
  }
  std::cout << "[ measured ] static trial, cam02: " << offsets[1].problem << "\n";
}

}  // namespace
}  // namespace mocap::camera
