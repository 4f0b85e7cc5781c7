// The windowed full fit (fit::WindowedFitter) against the one-solve full sequence on the held-out
// clip 07_01 (checks, not tuning): the same result for a track shorter than a window and close
// to it with windows; one output per frame, in order, as windows are solved; a cost per frame
// that does not grow with the track's length; a stop's budget.

#include <gtest/gtest.h>

#include <chrono>

#include <glm/geometric.hpp>

#include "fit/fit_fixture.hpp"
#include "fit/skeleton_fit.hpp"

namespace mocap {
namespace {

using Clock = std::chrono::steady_clock;

fit::FitOptions options() {
  fit::FitOptions o;
  o.camera = test::fit_camera();
  o.ground = GroundPlane{{0.0, 1.0, 0.0}, 0.0};  // the clip's world: y up
  return o;
}

// The fitter's inputs for `count` frames of a scene: its 2D, the truth turned 0.2 rad per bone
// (what a retrieval gives), camera poses; no contact flags (no database).
std::vector<fit::FrameInput> scene_inputs(const test::FitScene& s) {
  const auto retrieved = test::perturbed_truth(s.rendered.truth_camera, 0.2f, 5);
  return fit::make_inputs(s.rendered.input, retrieved, {}, s.cameras);
}

std::vector<fit::FittedFrame> windowed(const std::vector<fit::FrameInput>& inputs,
                                       fit::WindowOptions window, fit::FitStats* stats = nullptr) {
  fit::WindowedFitter fitter(options(), window);
  std::vector<fit::FittedFrame> out;
  for (const auto& in : inputs)
    for (auto& f : fitter.push(in)) out.push_back(f);
  for (auto& f : fitter.finish()) out.push_back(f);
  if (stats) *stats = fitter.stats();
  return out;
}

double mean_distance_mm(const std::vector<fit::FittedFrame>& a,
                        const std::vector<fit::FittedFrame>& b) {
  double sum = 0;
  int n = 0;
  for (std::size_t t = 0; t < a.size(); ++t)
    for (int j = 0; j < kBodyJoints; ++j) sum += glm::distance(a[t].joints[j], b[t].joints[j]), ++n;
  return 1000.0 * sum / n;
}

TEST(WindowedFit, ATrackShorterThanAWindowIsTheOneSolveFullSequence) {
  MOCAP_REQUIRE_FIT_CLIP();
  const auto inputs = scene_inputs(test::fit_scene(0, 40, 30.0f, 0.02f));
  const auto one = fit::fit_sequence(inputs, options());
  fit::WindowedFitter fitter(options(), {64, 16});
  for (const auto& in : inputs) EXPECT_TRUE(fitter.push(in).empty());  // nothing final yet
  const auto out = fitter.finish();
  ASSERT_EQ(out.size(), inputs.size());
  EXPECT_LT(mean_distance_mm(out, one.frames), 1e-3);
  for (int j = 0; j < kBodyJoints; ++j) EXPECT_NEAR(fitter.bones().m[j], one.bones.m[j], 1e-9);
}

TEST(WindowedFit, WindowsAgreeWithOneSolveOverTheWholeClip) {
  MOCAP_REQUIRE_FIT_CLIP();
  const auto s = test::fit_scene(0, 1000, 30.0f, 0.02f);
  const auto inputs = scene_inputs(s);
  ASSERT_GE(inputs.size(), 60u);
  const auto one = fit::fit_sequence(inputs, options());
  const auto win = windowed(inputs, {24, 8});  // several windows on this short clip
  ASSERT_EQ(win.size(), inputs.size());
  const double one_mm = test::mean_mpjpe_mm(one.frames, s.rendered.truth_camera);
  const double win_mm = test::mean_mpjpe_mm(win, s.rendered.truth_camera);
  EXPECT_LT(std::abs(win_mm - one_mm), 2.0) << "one solve " << one_mm << ", windows " << win_mm;
  EXPECT_LT(mean_distance_mm(win, one.frames), 15.0);  // absolute joints, camera frame
  // Every output has the bone lengths of the first window.
  fit::WindowedFitter fitter(options(), {24, 8});
  for (const auto& in : inputs) fitter.push(in);
  for (const auto& f : win) {
    const fit::BoneLengths b = fit::bone_lengths_of(f.joints);
    for (int j = 0; j < kBodyJoints; ++j) EXPECT_NEAR(b.m[j], fitter.bones().m[j], 1e-4);
  }
}

TEST(WindowedFit, FramesComeOutInOrderOneEachAsTheirWindowIsSolved) {
  MOCAP_REQUIRE_FIT_CLIP();
  auto inputs = scene_inputs(test::fit_scene(0, 60, 0.0f, 0.01f));
  auto absent = [&](std::size_t t) {  // no retrieval, no keypoints (the camera stays)
    inputs[t].retrieved_valid = false;
    inputs[t].keypoints = {};
  };
  for (std::size_t t = 30; t < 33; ++t) absent(t);  // a gap
  for (std::size_t t = 55; t < 60; ++t) absent(t);  // the person has left
  fit::WindowedFitter fitter(options(), {20, 5});
  std::vector<fit::FittedFrame> out;
  for (std::size_t t = 0; t < inputs.size(); ++t) {
    for (auto& f : fitter.push(inputs[t])) out.push_back(f);
    // A window of 20 is solved at frames 19, 34, 49: 15 frames become final each time.
    const std::size_t expected = t < 19 ? 0 : t < 34 ? 15 : t < 49 ? 30 : 45;
    EXPECT_EQ(out.size(), expected) << "after frame " << t;
    EXPECT_EQ(fitter.held(), t + 1 - expected);
  }
  for (auto& f : fitter.finish()) out.push_back(f);
  ASSERT_EQ(out.size(), inputs.size());
  for (std::size_t t = 0; t < out.size(); ++t) {
    EXPECT_EQ(out[t].observed, inputs[t].retrieved_valid) << t;
    EXPECT_EQ(out[t].valid, t < 55) << t;  // the gap is filled, the frames after the end are not
  }
  // The gap is filled smoothly: its bodies lie between their neighbours.
  for (std::size_t t = 30; t < 33; ++t) {
    const double step = glm::distance(out[t].root(), out[t - 1].root());
    EXPECT_LT(step, 0.1) << t;
  }
}

TEST(WindowedFit, TheCostPerFrameDoesNotGrowWithTheTrackLength) {
  MOCAP_REQUIRE_FIT_CLIP();
  // The clip at 96 frames per second: a long track of the same motion.
  const auto file = test::shared_data() / test::kFitClip;
  auto world = eval::load_truth({file.string()}, 96.0).front().world;
  ASSERT_GE(world.size(), 240u);
  const eval::TruthSequence truth{"07_01", world};
  auto scene = [&](std::size_t count) {
    test::FitScene s;
    s.world.assign(world.begin(), world.begin() + static_cast<std::ptrdiff_t>(count));
    s.rendered =
        eval::render({"07_01", s.world}, {"level", 30.0f, 1.5f, 0.0f, 4.5f}, {}, {0.02f, 0.0f}, 7);
    s.cameras = fit::moving_cameras(test::fit_camera(), s.world, s.rendered.truth_camera);
    return s;
  };
  fit::FitStats short_stats, long_stats;
  windowed(scene_inputs(scene(60)), {24, 8}, &short_stats);
  windowed(scene_inputs(scene(240)), {24, 8}, &long_stats);
  const double short_cost = short_stats.frame_iterations / 60.0;
  const double long_cost = long_stats.frame_iterations / 240.0;
  EXPECT_LT(long_cost, 1.5 * short_cost) << short_cost << " against " << long_cost;
  // Each window is at most 24 frames: its iterations are bounded, so is the work per frame.
  EXPECT_LE(long_stats.frame_iterations, 24.0 * options().max_iterations * long_stats.solves);
}

TEST(WindowedFit, AStopsBudgetBoundsTheLastSolve) {
  MOCAP_REQUIRE_FIT_CLIP();
  const auto inputs = scene_inputs(test::fit_scene(0, 60, 30.0f, 0.02f));
  fit::WindowedFitter held(options(), {16, 4});
  for (const auto& in : inputs) EXPECT_TRUE(held.push(in, false).empty());  // a stop: no solve
  const auto start = Clock::now();
  const auto quick = held.finish(fit::SolveBudget{3, 0.05});
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_EQ(quick.size(), inputs.size());
  for (const auto& f : quick) EXPECT_TRUE(f.valid);
  EXPECT_LE(held.stats().iterations, 4);  // Ceres counts the start as an iteration
  EXPECT_LT(seconds, 1.0);                // one solve of 60 frames, 3 iterations (ms in Release)
  // No time at all: the frames leave unplaced, at once.
  fit::WindowedFitter none(options(), {16, 4});
  for (const auto& in : inputs) none.push(in, false);
  const auto unplaced = none.finish(fit::SolveBudget{3, 0.0});
  ASSERT_EQ(unplaced.size(), inputs.size());
  for (const auto& f : unplaced) EXPECT_FALSE(f.valid);
  EXPECT_EQ(none.stats().solves, 0);
}

}  // namespace
}  // namespace mocap
