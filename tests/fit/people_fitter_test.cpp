// fit::PeopleFitter, the state behind recon.fit: every input frame comes out once, in order, with
// its people as they came in (placed where fitted); full mode streams frames out as windows are
// solved, holds the first window for the floor when it has to estimate one, keeps live mode's lag,
// and a stop finishes within its budget with every frame.

#include <gtest/gtest.h>

#include <chrono>

#include "fit/fit_fixture.hpp"
#include "fit/people_fitter.hpp"

namespace mocap {
namespace {

using Clock = std::chrono::steady_clock;

// Frames of two people (the clip seen from two sides, person 2 missing in frames 20-24), an
// untracked person (id -1) in each and an empty frame 50, as recon.temporal_selector sends them.
std::vector<People3D> stream(std::size_t frames) {
  const auto a = test::fit_scene(0, 1000, 30.0f, 0.01f);
  const auto b = test::fit_scene(0, 1000, 90.0f, 0.01f, 11);
  const auto pa = test::perturbed_truth(a.rendered.truth_camera, 0.1f, 3);
  const auto pb = test::perturbed_truth(b.rendered.truth_camera, 0.1f, 4);
  std::vector<People3D> out(frames);
  for (std::size_t t = 0; t < frames; ++t) {
    out[t].header.seq = t;
    if (t == 50) continue;
    const std::size_t f = t % a.world.size();
    auto person = [&](int id, const test::FitScene& s, const std::vector<recon::Pose3D>& p) {
      Person3D q;
      q.id = id;
      q.positions = p[f].joints;
      for (int j = 0; j < kBodyJoints; ++j)
        q.keypoints[j] = {s.rendered.input[f][3 * j], s.rendered.input[f][3 * j + 1],
                          s.rendered.input[f][3 * j + 2]};
      return q;
    };
    out[t].people.push_back(person(1, a, pa));
    if (t < 20 || t > 24) out[t].people.push_back(person(2, b, pb));
    out[t].people.push_back(person(-1, a, pa));
  }
  return out;
}

fit::PeopleFitOptions full_options() {
  fit::PeopleFitOptions o;
  o.mode = fit::StreamFitMode::full;
  o.fit.camera = test::fit_camera();
  o.window = {16, 4};
  o.calibrated_ground = GroundPlane{{0.0, -1.0, 0.0}, 1.5};  // 1.5 m under the camera
  return o;
}

// Every frame once, in order, its people as they came in; tracked people placed unless `stopped`
// (a stop's quick solve may leave the frames it had no time for unplaced).
void expect_every_frame_once_in_order(const std::vector<People3D>& in,
                                      const std::vector<People3D>& out, bool stopped = false) {
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t t = 0; t < out.size(); ++t) {
    EXPECT_EQ(out[t].header.seq, t);
    ASSERT_EQ(out[t].people.size(), in[t].people.size()) << "frame " << t;
    for (std::size_t i = 0; i < out[t].people.size(); ++i) {
      EXPECT_EQ(out[t].people[i].id, in[t].people[i].id);
      if (!stopped || in[t].people[i].id < 0) {
        EXPECT_EQ(out[t].people[i].placed, in[t].people[i].id >= 0) << "frame " << t;
      }
    }
  }
}

TEST(PeopleFitter, FullModeSendsFramesOutAsTheirWindowsAreSolved) {
  MOCAP_REQUIRE_FIT_CLIP();
  const auto in = stream(60);
  fit::PeopleFitter fitter(full_options());
  std::vector<People3D> out;
  for (std::size_t t = 0; t < in.size(); ++t) {
    for (auto& f : fitter.push(in[t])) out.push_back(std::move(f));
    if (t < 15) {
      EXPECT_TRUE(out.empty()) << t;  // nobody's first window is solved yet
    }
    EXPECT_EQ(out.size() + fitter.held_frames(), t + 1);
  }
  EXPECT_GE(out.size(), 36u);  // the windows of frames 0-15, 12-27, ... have been sent
  for (auto& f : fitter.finish()) out.push_back(std::move(f));
  expect_every_frame_once_in_order(in, out);
  EXPECT_EQ(fitter.placed(), 113);  // 59 + 54 person-frames (frame 50 is empty)
  for (const auto& f : out) {
    EXPECT_TRUE(f.has_ground);
    for (const auto& p : f.people)
      if (p.placed) {
        EXPECT_GT(p.root.translation.z, 1.0f);  // in front of the camera
      }
  }
}

TEST(PeopleFitter, WithAFloorToEstimateTheFirstWindowWaitsForIt) {
  MOCAP_REQUIRE_FIT_CLIP();
  const auto in = stream(40);
  auto options = full_options();
  options.calibrated_ground.reset();  // estimated from the feet (none in contact here: no floor)
  fit::PeopleFitter fitter(options);
  std::vector<People3D> out;
  for (std::size_t t = 0; t < 15; ++t) EXPECT_TRUE(fitter.push(in[t]).empty());
  out = fitter.push(in[15]);  // the 16th frame: the probe, then the windows
  EXPECT_FALSE(out.empty());
  for (std::size_t t = 16; t < in.size(); ++t)
    for (auto& f : fitter.push(in[t])) out.push_back(std::move(f));
  for (auto& f : fitter.finish()) out.push_back(std::move(f));
  expect_every_frame_once_in_order(in, out);
  EXPECT_FALSE(fitter.ground().has_value());
}

TEST(PeopleFitter, LiveModeKeepsItsLag) {
  MOCAP_REQUIRE_FIT_CLIP();
  const auto in = stream(30);
  auto options = full_options();
  options.mode = fit::StreamFitMode::live;
  options.fit.lag = 3;
  fit::PeopleFitter fitter(options);
  std::vector<People3D> out;
  for (std::size_t t = 0; t < in.size(); ++t) {
    for (auto& f : fitter.push(in[t])) out.push_back(std::move(f));
    EXPECT_EQ(out.size(), t >= 3 ? t - 2 : 0) << t;  // frame t - 3 leaves with frame t
  }
  for (auto& f : fitter.finish()) out.push_back(std::move(f));
  expect_every_frame_once_in_order(in, out);
  // Every frame timed once (fit::FrameTimes), its time in the summary the node reports.
  EXPECT_EQ(fitter.frame_times().count(), in.size());
  EXPECT_GT(fitter.frame_times().percentiles_ms()[1], 0.0);
  EXPECT_NE(fitter.summary().find(", per frame p50 "), std::string::npos) << fitter.summary();
}

// Percentiles by nearest rank over the last kSamples frames; nothing before the first.
TEST(FrameTimes, PercentilesOverTheLastFrames) {
  fit::FrameTimes times;
  EXPECT_EQ(times.describe("frame"), "");
  for (int ms = 1; ms <= 100; ++ms) times.add(std::chrono::milliseconds(ms));
  EXPECT_EQ(times.describe("frame"), "per frame p50 50.00 ms, p95 95.00 ms");
  // Older frames leave the window: kSamples frames of 2 ms push all of the above out.
  for (std::size_t i = 0; i < fit::FrameTimes::kSamples; ++i)
    times.add(std::chrono::milliseconds(2));
  EXPECT_EQ(times.describe("frame set"), "per frame set p50 2.00 ms, p95 2.00 ms");
  EXPECT_EQ(times.count(), 100u + fit::FrameTimes::kSamples);
}

TEST(PeopleFitter, AStopFinishesWithinItsBudgetWithEveryFrame) {
  MOCAP_REQUIRE_FIT_CLIP();
  const auto in = stream(150);
  fit::PeopleFitter fitter(full_options());
  std::vector<People3D> out;
  for (std::size_t t = 0; t < 30; ++t)
    for (auto& f : fitter.push(in[t])) out.push_back(std::move(f));
  fitter.stop();
  const int solves = fitter.stats().solves;
  const auto start = Clock::now();
  for (std::size_t t = 30; t < in.size(); ++t)
    for (auto& f : fitter.push(in[t])) out.push_back(std::move(f));
  EXPECT_EQ(fitter.stats().solves, solves);  // no window solved after the stop
  for (auto& f : fitter.finish()) out.push_back(std::move(f));
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_LT(seconds, 2.0);  // budget 0.25 s for the solves (a sanitizer build is slower)
  expect_every_frame_once_in_order(in, out, true);
  // What was sent before the stop was placed (frames 0-23 of both people: windows 0-15, 12-27).
  EXPECT_GE(fitter.placed(), 48);
}

}  // namespace
}  // namespace mocap
