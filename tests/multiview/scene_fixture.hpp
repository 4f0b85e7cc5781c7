#pragma once
// Virtual multi-view scenes for the tests: CMU *train* clips (never the held-out subjects) of five
// subjects with their own proportions, placed together in a room and seen by a ring of cameras
// (eval/multiview_scene.hpp), run through the reconstructor and scored.

#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "eval/multiview_scene.hpp"
#include "multiview/reconstructor.hpp"
#include "multiview/rig_reconstruction.hpp"
#include "support/shared_data.hpp"

namespace mocap::test {

inline constexpr double kSceneFps = 30.0;

// The clips, read once per test program (reading them takes most of a test's time).
inline const eval::TruthSequence& scene_clip(const std::string& name) {
  static std::map<std::string, eval::TruthSequence> clips;
  auto it = clips.find(name);
  if (it == clips.end()) {
    const auto file = shared_data() / "mocap" / "cmu31" / (name + ".bvh");
    it = clips.emplace(name, eval::load_truth({file.string()}, kSceneFps).front()).first;
  }
  return it->second;
}

// Long train clips of five subjects: walking about (03, 09, 91), jumps and kicks (86), the
// playground (01).
inline const std::vector<std::string>& scene_clip_names() {
  static const std::vector<std::string> names = {"09_12", "91_13", "86_01",
                                                 "03_03", "01_01", "03_04"};
  return names;
}

#define MOCAP_REQUIRE_SCENE_CLIPS()                                   \
  for (const std::string& clip : ::mocap::test::scene_clip_names()) { \
    MOCAP_REQUIRE_SHARED("mocap/cmu31/" + clip + ".bvh");             \
  }

// `count` people (at most 6), each from its own clip from `first_frame` on, placed in a 5 m x 5 m
// room so that during `frames` frames they stay in it and at least 0.5 m apart.
inline std::vector<eval::ScenePerson> scene_people(int count, int frames = 150,
                                                   int first_frame = 60) {
  std::vector<eval::ScenePerson> people;
  for (int i = 0; i < count; ++i) {
    eval::ScenePerson p;
    p.motion = &scene_clip(scene_clip_names()[static_cast<std::size_t>(i)]);
    p.first_frame = first_frame;
    people.push_back(p);
  }
  EXPECT_TRUE(eval::spread_people(people, frames, 2.5f, 0.5f, 1)) << "people placed too close";
  return people;
}

// `cameras` cameras of a ring of max(cameras, ring) evenly spaced ones: two cameras of a ring of
// four are 90 degrees apart, as a two-camera rig would be set up (opposite cameras see depth
// along their axis poorly).
inline std::vector<camera::Camera> scene_rig(int cameras, int ring = 0) {
  auto rig = eval::ring_rig(std::max(cameras, ring), 6.0, 1.6, 0.9, {0.0, 1.0, 0.0}, eval::Image{});
  rig.resize(static_cast<std::size_t>(cameras));
  return rig;
}

inline std::vector<multiview::ViewGeometry> geometries(const std::vector<camera::Camera>& rig) {
  std::vector<multiview::ViewGeometry> out;
  for (const auto& c : rig) out.push_back(multiview::from_camera(c));
  return out;
}

// The scene's degradation as the target condition: σ 2 % of the box height, 10 % joints
// dropped, 5 % outlier keypoints, false detections, occlusion.
inline eval::SceneDegradation target_degradation() {
  eval::SceneDegradation d;
  d.noise = 0.02f;
  d.dropout = 0.10f;
  d.outliers = 0.05f;
  d.false_detections = 0.2f;
  return d;
}

struct SceneRun {
  eval::SceneScore score;
  std::vector<multiview::FrameResult> results;
};

inline SceneRun run_scene(const std::vector<eval::ScenePerson>& people, int cameras, int frames,
                          const eval::SceneDegradation& degradation,
                          const multiview::ReconstructionOptions& options = {},
                          std::uint64_t seed = 1, bool keep_results = false) {
  const auto rig = scene_rig(cameras, 4);
  eval::SceneRenderer renderer(rig, seed);
  multiview::ReconstructionOptions o = options;
  o.tracker.fps = kSceneFps;
  multiview::MultiViewReconstructor reconstructor(geometries(rig), multiview::KeypointSet::body15(),
                                                  o);
  eval::SceneScorer scorer(static_cast<int>(people.size()));
  multiview::FrameObservations observations;
  SceneRun run;
  for (int f = 0; f < frames; ++f) {
    const eval::SceneFrame frame = renderer.render(people, f, degradation);
    eval::SceneRenderer::to_observations(frame, observations);
    const multiview::FrameResult& result = reconstructor.process(observations, f);
    scorer.add(frame, result);
    if (keep_results) run.results.push_back(result);
  }
  run.score = scorer.score();
  return run;
}

inline std::string describe(const eval::SceneScore& s) {
  return "person-frames " + std::to_string(s.person_frames) + ", reconstructed " +
         std::to_string(s.reconstructed) + ", wrong " + std::to_string(s.wrong_associations) +
         ", false " + std::to_string(s.false_people) + ", duplicates " +
         std::to_string(s.duplicates) + ", id switches " + std::to_string(s.id_switches) +
         ", MPJPE " + std::to_string(s.mpjpe_mm()) + " mm, single-view " +
         std::to_string(s.single_view);
}

}  // namespace mocap::test
