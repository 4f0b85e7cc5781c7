// multiview.reconstruct in the single-node harness: People2D of four views made by projecting CMU
// *train* mocap (two people of the virtual scenes, tests/multiview/scene_fixture.hpp) through a
// rig built here, with lens distortion, written as a TOML rig file; the node must give the people
// back in the world, with stable ids, also from partial sets; and the bad input it refuses. With
// `fit: live`, noisy keypoints: constant bones, closer to the truth than the triangulation, one
// output per set in order.

#include <cmath>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "camera/rig_file.hpp"
#include "core/input_error.hpp"
#include "graph/harness.hpp"
#include "multiview/scene_fixture.hpp"
#include "support/files.hpp"

namespace mocap::test {
namespace {

constexpr int kFrames = 24;
constexpr int kCameras = 4;

camera::Rig scene_camera_rig() {
  camera::Rig rig;
  int i = 0;
  for (camera::Camera c : scene_rig(kCameras)) {
    c.name = "cam_" + std::to_string(i++);
    c.distortion = {-0.05, 0.01, 0.0, 0.0};  // the node must undistort
    rig.cameras.push_back(c);
  }
  return rig;
}

// The people of scene frame `f` seen by camera `c`, in HumanEva-15 (a keypoint per body joint),
// with Gaussian noise of `noise_px` pixels (from `random`) when given.
People2D project(const camera::Camera& c, const std::vector<eval::ScenePerson>& people, int f,
                 std::mt19937* random = nullptr, double noise_px = 0.0) {
  std::normal_distribution<double> noise(0.0, noise_px);
  People2D out;
  out.header.frame = f;
  out.header.capture_ns = static_cast<std::int64_t>(f * 1e9 / kSceneFps);
  out.layout = LayoutId::humaneva15;
  out.camera = c.name;
  const KeypointLayout& l = layout(LayoutId::humaneva15);
  for (const auto& person : people) {
    const auto body = person.at(f);
    if (!body) continue;
    Person2D p;
    p.joints.resize(l.keypoints.size());
    for (int j = 0; j < kBodyJoints; ++j) {
      glm::dvec2 px = c.project(glm::dvec3((*body)[j]));
      if (random) px += glm::dvec2(noise(*random), noise(*random));
      if (!std::isfinite(px.x) || px.x < 0 || px.y < 0 || px.x > c.width || px.y > c.height)
        continue;
      p.joints[l.body[j].first] = {static_cast<float>(px.x), static_cast<float>(px.y), 0.9f};
    }
    out.people.push_back(std::move(p));
  }
  return out;
}

struct Fixture {
  TempDir dir;
  camera::Rig rig = scene_camera_rig();
  std::string rig_file = dir.file("rig.toml");
  std::vector<eval::ScenePerson> people = scene_people(2, kFrames);
  Fixture() { camera::write_rig(rig_file, rig); }
};

graph::HarnessOptions views(std::size_t n) {
  graph::HarnessOptions o;
  o.repeated["view"] = n;
  return o;
}

TEST(MultiViewNode, PeopleInTheWorldWithStableIdsFromFullAndPartialSets) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  Fixture fx;
  graph::Harness node("multiview.reconstruct", {{"rig", fx.rig_file}, {"fps", "30"}},
                      views(kCameras));
  for (int f = 0; f < kFrames; ++f) {
    for (int c = 0; c < kCameras; ++c) {
      if (c == 3 && f >= kFrames / 2) continue;  // camera 3 stops: partial sets from here on
      node.push("view", project(fx.rig.cameras[c], fx.people, f), static_cast<std::size_t>(c));
    }
  }
  node.finish();
  const auto out = node.pull<People3D>("out");
  ASSERT_EQ(out.size(), static_cast<std::size_t>(kFrames));
  const auto sync = node.stats().sync;
  EXPECT_EQ(sync.sets - sync.complete, static_cast<std::uint64_t>(kFrames / 2));
  std::map<std::size_t, int> id_of;  // scene person -> id
  double error_sum = 0.0;
  int joints = 0;
  for (int f = 2; f < kFrames; ++f) {  // people are confirmed from their third frame
    const People3D& frame = *out[static_cast<std::size_t>(f)];
    EXPECT_TRUE(frame.frame.is_world());
    EXPECT_EQ(frame.header.frame, f);
    ASSERT_EQ(frame.people.size(), fx.people.size()) << "frame " << f;
    for (const Person3D& p : frame.people) {
      const auto world = joints_in_frame(p);
      // The scene person nearest to this one's root.
      std::size_t best = 0;
      float best_d = 1e9f;
      for (std::size_t s = 0; s < fx.people.size(); ++s) {
        const float d =
            glm::distance((*fx.people[s].at(f))[index(Joint::root)], world[index(Joint::root)]);
        if (d < best_d) best_d = d, best = s;
      }
      const auto truth = *fx.people[best].at(f);
      for (int j = 0; j < kBodyJoints; ++j) {
        ASSERT_TRUE(std::isfinite(world[j].x)) << "frame " << f << " joint " << j;
        error_sum += glm::distance(world[j], truth[j]);
        ++joints;
      }
      const auto [it, fresh] = id_of.emplace(best, p.id);
      EXPECT_EQ(it->second, p.id) << "id of scene person " << best << " changed at frame " << f;
    }
  }
  EXPECT_EQ(id_of.size(), fx.people.size());
  // Exact projections through a distorted lens: what is left is the undistortion's and the
  // tracks' prior (a few millimetres); a wrong camera, axis or lens gives decimetres.
  std::cout << "mean joint error " << 1000 * error_sum / joints << " mm over " << joints
            << " joints\n";
  EXPECT_LT(error_sum / joints, 0.01) << "mean joint error, metres";
  EXPECT_NE(node.status().find("cam_3 missing in 12"), std::string::npos) << node.status();
}

// The mean distance of the people's joints to the nearest scene person's, and per id the
// standard deviation of each bone's length (the largest), from frame `from` on.
struct Accuracy {
  double mean_error_m = 0.0;
  double worst_bone_std_m = 0.0;
  int joints = 0;
};

Accuracy accuracy(const std::vector<std::shared_ptr<const People3D>>& out,
                  const std::vector<eval::ScenePerson>& people, int from) {
  Accuracy a;
  double sum = 0.0;
  std::map<int, std::array<std::vector<double>, kBodyJoints>> bones;  // id -> per joint
  for (std::size_t f = static_cast<std::size_t>(from); f < out.size(); ++f) {
    for (const Person3D& p : out[f]->people) {
      const auto world = joints_in_frame(p);
      double best = 1e9;
      for (const auto& s : people) {
        double d = 0.0;
        for (int j = 0; j < kBodyJoints; ++j)
          d += glm::distance(world[j], (*s.at(static_cast<int>(f)))[j]) / kBodyJoints;
        best = std::min(best, d);
      }
      sum += best * kBodyJoints;
      a.joints += kBodyJoints;
      for (int j = 0; j < kBodyJoints; ++j) {
        if (kJointParent[j] >= 0)  // the root has none
          bones[p.id][j].push_back(glm::distance(world[j], world[kJointParent[j]]));
      }
    }
  }
  a.mean_error_m = a.joints > 0 ? sum / a.joints : 1e9;
  for (const auto& [id, lengths] : bones) {
    for (const auto& l : lengths) {
      if (l.size() < 2) continue;
      double mean = 0.0, square = 0.0;
      for (double x : l) mean += x / static_cast<double>(l.size());
      for (double x : l) square += (x - mean) * (x - mean) / static_cast<double>(l.size());
      a.worst_bone_std_m = std::max(a.worst_bone_std_m, std::sqrt(square));
    }
  }
  return a;
}

TEST(MultiViewNode, LiveFitGivesConstantBonesCloserToTheTruthOneOutputPerSetInOrder) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  constexpr int kFitFrames = 40;
  Fixture fx;
  fx.people = scene_people(2, kFitFrames);
  std::vector<Accuracy> results;
  for (const char* mode : {"off", "live"}) {
    graph::Harness node("multiview.reconstruct",
                        {{"rig", fx.rig_file}, {"fit", mode}, {"bone_frames", "10"}},
                        views(kCameras));
    std::mt19937 random(7);  // the same noise for both modes
    for (int f = 0; f < kFitFrames; ++f)
      for (int c = 0; c < kCameras; ++c)
        node.push("view", project(fx.rig.cameras[c], fx.people, f, &random, 4.0),
                  static_cast<std::size_t>(c));
    node.finish();
    const auto out = node.pull<People3D>("out");
    ASSERT_EQ(out.size(), static_cast<std::size_t>(kFitFrames)) << mode;
    for (int f = 0; f < kFitFrames; ++f) {
      EXPECT_EQ(out[static_cast<std::size_t>(f)]->header.frame, f) << mode;
      if (f >= 2) {  // people are confirmed from their third frame
        EXPECT_EQ(out[static_cast<std::size_t>(f)]->people.size(), 2u) << mode << f;
      }
    }
    results.push_back(accuracy(out, fx.people, 2));
    std::cout << "fit " << mode << ": mean joint error " << 1000 * results.back().mean_error_m
              << " mm, worst bone-length std " << 1000 * results.back().worst_bone_std_m << " mm; "
              << node.status() << "\n";
    if (std::string(mode) == "live") {
      EXPECT_NE(node.status().find("live fit: 76 of 76 person-frames fitted, 2 tracks"),
                std::string::npos)
          << node.status();
      // Its time per frame set (fit::FrameTimes, shared with the monocular fit).
      EXPECT_NE(node.status().find(", per frame set p50 "), std::string::npos) << node.status();
    }
  }
  EXPECT_GT(results[0].worst_bone_std_m, 0.005);   // 4 px of noise: triangulated bones vary
  EXPECT_LT(results[1].worst_bone_std_m, 0.0001);  // fitted: one skeleton per track
  EXPECT_LT(results[1].mean_error_m, results[0].mean_error_m);
}

TEST(MultiViewNode, AViewLaterThanItsSetIsCountedAndDroppedNotSolvedAsASecondSet) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  // Live: camera 1's detector is more than sync_wait_ms late with frame 0. Set 0 goes on partial;
  // the late view must not make a second People3D of frame 0 (poses.jsonl keeps one line per
  // frame number): it is counted late and dropped.
  using namespace std::chrono_literals;
  Fixture fx;
  graph::Harness node("multiview.reconstruct",
                      {{"rig", fx.rig_file}, {"sync_wait_ms", "30"}, {"report_tentative", "true"}},
                      views(2));
  node.push("view", project(fx.rig.cameras[0], fx.people, 0), 0);
  EXPECT_EQ(node.process_ready(), 0u);  // taken in: set 0 waits for view 1
  std::this_thread::sleep_for(60ms);
  EXPECT_EQ(node.process_ready(), 1u);  // set 0, partial: its wait is over
  node.push("view", project(fx.rig.cameras[1], fx.people, 0), 1);  // late
  for (int f = 1; f < 4; ++f)
    for (std::size_t c = 0; c < 2; ++c)
      node.push("view", project(fx.rig.cameras[c], fx.people, f), c);
  node.finish();
  std::vector<std::int64_t> frames;
  for (const auto& out : node.pull<People3D>("out")) frames.push_back(out->header.frame);
  EXPECT_EQ(frames, (std::vector<std::int64_t>{0, 1, 2, 3}));
  const auto sync = node.stats().sync;
  EXPECT_EQ(sync.sets, 4u);
  EXPECT_EQ(sync.complete, 3u);
  EXPECT_EQ(sync.inputs[1].late, 1u);
  EXPECT_EQ(sync.inputs[1].late_dropped, 1u);
}

TEST(MultiViewNode, AFitModeItDoesNotKnowIsRefusedByGraphValidation) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  Fixture fx;
  try {
    graph::Harness node("multiview.reconstruct", {{"rig", fx.rig_file}, {"fit", "ful"}}, views(2));
    FAIL() << "fit: ful was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("full"), std::string::npos) << e.what();
  }
}

TEST(MultiViewNode, ACameraTheRigLacksIsRefusedByName) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  Fixture fx;
  graph::Harness node("multiview.reconstruct", {{"rig", fx.rig_file}}, views(2));
  People2D a = project(fx.rig.cameras[0], fx.people, 0);
  People2D b = project(fx.rig.cameras[1], fx.people, 0);
  b.camera = "cam_left";
  node.push("view", a, 0);
  node.push("view", b, 1);
  try {
    node.finish();
    FAIL() << "a view of camera cam_left was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'cam_left'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(fx.rig_file), std::string::npos) << e.what();
  }
}

TEST(MultiViewNode, MoreViewsThanCamerasOrAnUnreadableRigAreRefused) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  Fixture fx;
  {
    graph::Harness node("multiview.reconstruct", {{"rig", fx.rig_file}}, views(kCameras + 1));
    EXPECT_THROW(node.open(), InputError);
  }
  for (const std::string text : {"", "[cam_0]\nname = \"cam_0\"\nsize = [", "\x01\x02garbage"}) {
    const std::string bad = fx.dir.file("bad.toml");
    write_file(bad, text);
    graph::Harness node("multiview.reconstruct", {{"rig", bad}}, views(2));
    try {
      node.open();
      FAIL() << "rig '" << text << "' was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mocap::test
