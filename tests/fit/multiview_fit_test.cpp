// The skeleton fit on several views (fit/multiview_fit.hpp) on virtual scenes of CMU train clips:
// 3 people, 4 cameras, the target degradation (σ 2 %, drops, outliers, false detections,
// occlusion), reconstructed by components/multiview and then fitted live and in full.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "fit/multiview_fit.hpp"
#include "fit/multiview_input.hpp"
#include "fit/multiview_people_fitter.hpp"
#include "fit/scene_fit.hpp"
#include "multiview/scene_fixture.hpp"
#include "stream_fit.hpp"

namespace mocap::fit {
namespace {

constexpr int kFrames = 90;
constexpr int kCameras = 4;

struct Scene {
  std::vector<camera::Camera> rig;
  std::vector<eval::SceneFrame> frames;
  std::vector<multiview::FrameObservations> input;
  std::vector<multiview::FrameResult> results;
};

Scene reconstruct(int people_count, std::uint64_t seed = 1) {
  Scene s;
  const auto people = test::scene_people(people_count, kFrames);
  s.rig = test::scene_rig(kCameras, 4);
  eval::SceneRenderer renderer(s.rig, seed);
  multiview::ReconstructionOptions options;
  options.tracker.fps = test::kSceneFps;
  multiview::MultiViewReconstructor reconstructor(test::geometries(s.rig),
                                                  multiview::KeypointSet::body15(), options);
  for (int f = 0; f < kFrames; ++f) {
    s.frames.push_back(renderer.render(people, f, test::target_degradation()));
    eval::SceneRenderer::to_observations(s.frames.back(), s.input.emplace_back());
    s.results.push_back(reconstructor.process(s.input.back(), f));
  }
  return s;
}

eval::SceneScore score(const Scene& s, const std::vector<multiview::FrameResult>& results) {
  eval::SceneScorer scorer(static_cast<int>(s.frames.front().truth.size()));
  for (std::size_t f = 0; f < s.frames.size(); ++f) scorer.add(s.frames[f], results[f]);
  return scorer.score();
}

// The largest, over tracks and bones, standard deviation of a bone's length (metres).
double worst_bone_std_m(const std::vector<multiview::FrameResult>& results) {
  std::map<int, std::array<std::vector<double>, kBodyJoints>> lengths;
  for (const auto& r : results)
    for (std::size_t p = 0; p < r.people.size(); ++p) {
      if (r.people[p].id < 0) continue;
      const auto body = r.body_of(p);
      for (int j = 0; j < kBodyJoints; ++j) {
        if (kJointParent[j] < 0) continue;
        if (!body[j].valid() || !body[kJointParent[j]].valid()) continue;
        lengths[r.people[p].id][j].push_back(
            glm::distance(body[j].position, body[kJointParent[j]].position));
      }
    }
  double worst = 0.0;
  for (const auto& [id, bones] : lengths)
    for (const auto& v : bones) {
      if (v.size() < 2) continue;
      double mean = 0.0, var = 0.0;
      for (double x : v) mean += x;
      mean /= static_cast<double>(v.size());
      for (double x : v) var += (x - mean) * (x - mean);
      worst = std::max(worst, std::sqrt(var / static_cast<double>(v.size())));
    }
  return worst;
}

MultiViewFitOptions options_for(const Scene& s) {
  MultiViewFitOptions o;
  o.cameras = s.rig;
  o.fit = multiview_fit_defaults();
  o.fit.ground = GroundPlane{{0.0, 1.0, 0.0}, 0.0};  // the scene's floor: y = 0, y up
  return o;
}

TEST(MultiViewFit, LiveAndFullBeatTheTriangulationWithConstantBones) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  const Scene s = reconstruct(3);
  const eval::SceneScore triangulated = score(s, s.results);
  ASSERT_GT(triangulated.reconstructed, 200) << test::describe(triangulated);
  const MultiViewFitOptions options = options_for(s);
  for (const bool live : {true, false}) {
    std::vector<multiview::FrameResult> results = s.results;
    const TrackFits fits = fit_tracks(s.input, results, options, live);
    const eval::SceneScore fitted = score(s, results);
    SCOPED_TRACE(live ? "live" : "full");
    EXPECT_GE(fits.tracks, 3);
    // Every reconstructed person of a track gets a fitted body of all 15 joints.
    EXPECT_EQ(fits.person_frames, triangulated.reconstructed + triangulated.duplicates);
    EXPECT_EQ(fitted.joints, 15 * fitted.reconstructed);
    // Fewer joints triangulated than fitted, yet the fit is clearly closer to the truth.
    EXPECT_LT(fitted.mpjpe_mm(), 0.9 * triangulated.mpjpe_mm())
        << "triangulated " << test::describe(triangulated) << "\nfitted " << test::describe(fitted);
    // One skeleton per track: the triangulation's bones vary by centimetres, the fit's not at all.
    EXPECT_GT(worst_bone_std_m(s.results), 0.01);
    EXPECT_LT(worst_bone_std_m(results), 1e-4);
    EXPECT_EQ(fitted.id_switches, triangulated.id_switches);
  }
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

TEST(MultiViewFit, FullModeWindowsJoinAsSmoothlyAsTheyMoveInside) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  // The stream's full mode (MultiViewPeopleFitter) in windows of 30 sets, 10 of them solved again
  // with the next: each window is solved after the two frames emitted before it (frozen), so the
  // motion across a join is as smooth as inside a window. Solved alone, each window's first frames
  // moved by centimetres against the previous window's last ones.
  const Scene s = reconstruct(2);
  MultiViewPeopleFitOptions o;
  o.mode = StreamFitMode::full;
  o.fit = options_for(s);
  o.window = {30, 10};
  MultiViewPeopleFitter fitter(o);
  const std::vector<People3D> out = test::fit_stream(fitter, s.input, s.results);
  ASSERT_EQ(out.size(), s.results.size());
  // Per track, its fitted joints by frame; the acceleration |p(f+1) - 2 p(f) + p(f-1)| of every
  // joint at the two frames either side of a join (frames 20k - 1 and 20k of the track: windows
  // emit 20 frames each) and inside.
  std::map<int, std::vector<std::pair<std::int64_t, Body>>> tracks;
  for (const People3D& frame : out)
    for (const Person3D& p : frame.people)
      if (p.placed) tracks[p.id].emplace_back(frame.header.frame, joints_in_frame(p));
  std::vector<double> at_join, inside;
  int joins = 0;
  for (const auto& [id, track] : tracks) {
    for (std::size_t k = 1; k + 1 < track.size(); ++k) {
      if (track[k + 1].first - track[k - 1].first != 2) continue;  // a gap
      const bool join = (k + 1) % 20 == 0 || k % 20 == 0;
      joins += k % 20 == 0 ? 1 : 0;
      for (int j = 0; j < kBodyJoints; ++j) {
        const glm::vec3 a =
            track[k + 1].second[j] - 2.0f * track[k].second[j] + track[k - 1].second[j];
        (join ? at_join : inside).push_back(1000.0 * glm::length(a));
      }
    }
  }
  ASSERT_GE(joins, 6);
  const double join_max = *std::max_element(at_join.begin(), at_join.end());
  const double inside_max = *std::max_element(inside.begin(), inside.end());
  std::cout << joins << " joins: acceleration at the joins median " << median(at_join)
            << " mm, max " << join_max << " mm; inside median " << median(inside) << " mm, max "
            << inside_max << " mm\n";
  EXPECT_LT(median(at_join), 1.5 * median(inside));
  EXPECT_LT(join_max, inside_max);
}

// The stream's live fit of scene `s` over the frames `frames` (indices into the scene), each
// pushed with the frame number `numbers[i]`: each person's fitted joints by scene frame and id.
std::map<std::pair<std::size_t, int>, Body> live_fit(const Scene& s,
                                                     const std::vector<std::size_t>& frames,
                                                     const std::vector<std::int64_t>& numbers) {
  MultiViewPeopleFitOptions o;
  o.mode = StreamFitMode::live;
  o.fit = options_for(s);
  MultiViewPeopleFitter fitter(o);
  const std::vector<People3D> out = test::fit_stream(fitter, s.input, s.results, frames, numbers);
  std::map<std::pair<std::size_t, int>, Body> fitted;
  for (const People3D& frame : out)
    for (const Person3D& p : frame.people)
      if (p.placed) fitted[{frames[frame.header.seq], p.id}] = joints_in_frame(p);
  return fitted;
}

TEST(MultiViewFit, LiveFitTakesAGapOfKSetsAsKSteps) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  // flow.set_limiter drops whole sets while the detectors are busy and numbers the sets it
  // passes with gaps: frames 40-44 never reach the fit. Pushed with their frame numbers, the
  // smoothness terms take the gap as 6 steps and the fit around it is the fit of the same motion
  // sampled without the gap; taken as one step (the frames renumbered 0, 1, 2, ...), the motion
  // of 6 frames looks like a jump and is smoothed away.
  const Scene s = reconstruct(1);
  std::vector<std::size_t> all, gapped;
  for (std::size_t f = 0; f < s.results.size(); ++f) {
    all.push_back(f);
    if (f < 40 || f > 44) gapped.push_back(f);
  }
  std::vector<std::int64_t> all_numbers(all.begin(), all.end());
  std::vector<std::int64_t> gapped_numbers(gapped.begin(), gapped.end()), renumbered;
  for (std::size_t i = 0; i < gapped.size(); ++i)
    renumbered.push_back(static_cast<std::int64_t>(i));
  const auto dense = live_fit(s, all, all_numbers);
  const auto with_gap = live_fit(s, gapped, gapped_numbers);
  const auto as_one_step = live_fit(s, gapped, renumbered);
  // The mean joint distance to the dense fit over the 4 frames either side of the gap.
  const auto distance_mm = [&](const std::map<std::pair<std::size_t, int>, Body>& fit) {
    double sum = 0.0;
    int n = 0;
    for (const auto& [key, body] : dense) {
      if (!((key.first >= 36 && key.first < 40) || (key.first > 44 && key.first <= 48))) continue;
      const auto it = fit.find(key);
      if (it == fit.end()) continue;
      for (int j = 0; j < kBodyJoints; ++j, ++n)
        sum += 1000.0 * glm::distance(body[j], it->second[j]);
    }
    EXPECT_EQ(n, 8 * kBodyJoints);
    return n > 0 ? sum / n : 1e9;
  };
  const double gap_mm = distance_mm(with_gap), one_step_mm = distance_mm(as_one_step);
  std::cout << "around a gap of 5 sets, mean joint distance to the fit without the gap: " << gap_mm
            << " mm with the frame numbers, " << one_step_mm << " mm with the gap as one step\n";
  EXPECT_LT(gap_mm, 7.0);  // measured 4.5 mm (the 5 sets' keypoints are missing)
  EXPECT_GT(one_step_mm, 2.0 * gap_mm);
}

TEST(MultiViewFit, ExactKeypointsGiveTheTruthBack) {
  MOCAP_REQUIRE_SCENE_CLIPS();
  // One person, noiseless keypoints in every camera, the truth as the triangulation: the fit
  // keeps the body where it is (a bias of any term would move it).
  const auto people = test::scene_people(1, 30);
  const auto rig = test::scene_rig(kCameras, 4);
  MultiViewFitOptions options;
  options.cameras = rig;
  options.fit = multiview_fit_defaults();
  std::vector<MultiViewFrameInput> frames(30);
  for (int f = 0; f < 30; ++f) {
    const Body truth = *people[0].at(f);
    frames[f].triangulated = truth;
    for (int v = 0; v < kCameras; ++v) {
      ViewKeypoints& view = frames[f].views.emplace_back();
      view.camera = v;
      for (int j = 0; j < kBodyJoints; ++j) {
        const glm::dvec2 px = options.cameras[v].project(glm::dvec3(truth[j]));
        view.keypoints[3 * j] = static_cast<float>(px.x);
        view.keypoints[3 * j + 1] = static_cast<float>(px.y);
        view.keypoints[3 * j + 2] = 1.0f;
      }
    }
  }
  const FitResult full = fit_multiview_sequence(frames, options);
  MultiViewLiveFitter live(options);
  std::vector<FittedFrame> live_frames;
  for (const auto& f : frames)
    for (auto& r : live.push(f)) live_frames.push_back(r);
  for (auto& r : live.finish()) live_frames.push_back(r);
  ASSERT_EQ(live_frames.size(), frames.size());
  double full_mm = 0.0, live_mm = 0.0;
  for (int f = 0; f < 30; ++f) {
    ASSERT_TRUE(full.frames[f].valid);
    ASSERT_TRUE(live_frames[f].valid);
    for (int j = 0; j < kBodyJoints; ++j) {
      full_mm += 1000.0 * glm::distance(full.frames[f].joints[j], frames[f].triangulated[j]);
      live_mm += 1000.0 * glm::distance(live_frames[f].joints[j], frames[f].triangulated[j]);
    }
  }
  EXPECT_LT(full_mm / (30 * kBodyJoints), 3.0);
  EXPECT_LT(live_mm / (30 * kBodyJoints), 3.0);
}

TEST(MultiViewFit, UnseenFramesAndBadCameraIndices) {
  MultiViewFitOptions options;
  options.cameras = {camera::Camera::from_fov(640, 480, 60.0)};
  options.fit = multiview_fit_defaults();
  // Nothing triangulated: nothing fitted, nothing thrown.
  const std::vector<MultiViewFrameInput> empty(5);
  const FitResult none = fit_multiview_sequence(empty, options);
  ASSERT_EQ(none.frames.size(), 5u);
  for (const auto& f : none.frames) EXPECT_FALSE(f.valid);
  MultiViewLiveFitter live(options);
  for (const auto& f : empty) {
    for (const auto& out : live.push(f)) EXPECT_FALSE(out.valid);
  }
  for (const auto& f : live.finish()) EXPECT_FALSE(f.valid);
  // Keypoints of a camera the rig does not have: refused, naming it.
  std::vector<MultiViewFrameInput> bad(1);
  bad[0].triangulated.fill(glm::vec3(0.0f, 1.0f, 3.0f));
  bad[0].views.push_back({3, {}});
  try {
    fit_multiview_sequence(bad, options);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("camera 3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mocap::fit
