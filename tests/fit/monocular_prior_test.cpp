// The monocular prior of the multi-view fit (fit/monocular_prior.hpp) on a real clip: one second
// of HumanEva-I S1 seen by C1 and C2 (83 degrees apart), ground-truth 2D, the right elbow and
// wrist hidden from C2, so that only C1 sees them and nothing but a prior gives their depth. The
// prior retrieves from a real database (the small test database of CMU walking, running and a
// bow). A prior turned to the wrong depth shows the test can fail: it reprojects exactly as the
// right one in C1, so only the prior decides where the arm goes.

#include "fit/monocular_prior.hpp"

#include <bit>
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "eval/humaneva_multiview.hpp"
#include "fit/multiview_input.hpp"
#include "fit/multiview_people_fitter.hpp"
#include "multiview/rig_reconstruction.hpp"
#include "stream_fit.hpp"
#include "support/small_pose_database.hpp"

namespace mocap::fit {
namespace {

namespace he = io::humaneva;

constexpr std::size_t kFrames = 24;
constexpr std::array<int, 2> kHidden = {index(Joint::right_elbow), index(Joint::right_wrist)};

struct Clip {
  std::vector<camera::Camera> rig;                  // C1, C2
  std::vector<multiview::FrameObservations> input;  // C2 without the right elbow and wrist
  std::vector<multiview::FrameResult> results;      // triangulated and tracked
  std::vector<Body> truth;                          // HumanEva's world
};

// A joint hidden from C2 in one frame only (besides kHidden in every frame).
struct OneFrameDrop {
  int joint = -1;
  std::size_t frame = 0;
};

Clip reconstruct(const posedb::Database& db, OneFrameDrop drop = {}) {
  const auto folder = test::shared_data() / "eval/humaneva_i_videopose3d";
  const auto cameras = he::load_cameras(folder / he::kCamerasFile);
  const auto sequences =
      eval::humaneva_validation_sequences(he::load_dataset(folder), cameras, db.build_info().fps);
  std::size_t first = 0;  // the first chunk of a second or more; its C1, C2, C3 follow
  while (first + 3 <= sequences.size() && sequences[first].input.size() < kFrames) first += 3;
  if (first + 3 > sequences.size()) throw std::runtime_error("no Validate chunk of a second");
  const std::vector<eval::HumanEvaSequence> chunk(sequences.begin() + first,
                                                  sequences.begin() + first + 3);
  const eval::HumanEvaTake take = eval::humaneva_takes(chunk, cameras).front();
  Clip c;
  c.rig = {chunk[0].camera, chunk[1].camera};
  c.truth.assign(take.truth_world.begin(), take.truth_world.begin() + kFrames);
  multiview::ReconstructionOptions options;
  options.tracker.fps = static_cast<float>(db.build_info().fps);
  multiview::MultiViewReconstructor reconstructor(
      {multiview::from_camera(c.rig[0]), multiview::from_camera(c.rig[1])},
      multiview::KeypointSet::body15(), options);
  for (std::size_t f = 0; f < kFrames; ++f) {
    multiview::FrameObservations& obs = c.input.emplace_back();
    obs.reset(2, kBodyJoints);
    for (int v = 0; v < 2; ++v) {
      const recon::BodyXyc& in = chunk[static_cast<std::size_t>(v)].input[f];
      const std::span<float> xyc = obs.add_person(v);
      for (int j = 0; j < kBodyJoints; ++j) {
        if (v == 1 && (j == kHidden[0] || j == kHidden[1])) continue;  // C2 does not see them
        if (v == 1 && j == drop.joint && f == drop.frame) continue;
        const glm::dvec2 p =
            c.rig[static_cast<std::size_t>(v)].undistort_pixel({in[3 * j], in[3 * j + 1]});
        xyc[3 * j] = static_cast<float>(p.x);
        xyc[3 * j + 1] = static_cast<float>(p.y);
        xyc[3 * j + 2] = in[3 * j + 2];
      }
    }
    c.results.push_back(reconstructor.process(obs, static_cast<std::int64_t>(f)));
  }
  return c;
}

// The subject's fit inputs, frame by frame (a frame without them: a gap), with the prior when
// given; `flip_depth`: the hidden bones' prior mirrored through C1's image plane (the same image
// in C1, the other depth).
std::vector<MultiViewFrameInput> inputs(const Clip& c, MonocularPrior* prior, bool flip_depth,
                                        int* with_prior) {
  std::vector<MultiViewFrameInput> out(c.results.size());
  for (std::size_t f = 0; f < c.results.size(); ++f) {
    const multiview::FrameResult& r = c.results[f];
    if (r.people.empty() || r.people.front().id < 0) continue;
    multiview_input(c.input[f], r, 0, multiview::KeypointSet::body15(), out[f]);
    if (!prior || !prior->add(out[f], r.body_of(0), c.rig)) continue;
    ++*with_prior;
    if (!flip_depth) continue;
    const glm::dvec3 axis = glm::transpose(c.rig[0].rotation) * glm::dvec3(0.0, 0.0, 1.0);
    for (const int b : kHidden) {
      const glm::dvec3 d(out[f].prior.direction[b]);
      out[f].prior.direction[b] = glm::vec3(d - 2.0 * glm::dot(d, axis) * axis);
    }
  }
  return out;
}

// Mean distance (mm) of the hidden joints to the truth over the fitted frames, and how many.
std::pair<double, int> hidden_error_mm(const Clip& c, const FitResult& fit) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t f = 0; f < fit.frames.size(); ++f) {
    if (!fit.frames[f].valid || !fit.frames[f].observed) continue;
    for (const int j : kHidden) sum += glm::distance(fit.frames[f].joints[j], c.truth[f][j]);
    ++n;
  }
  return {n > 0 ? 1000.0 * sum / (2.0 * n) : NAN, n};
}

TEST(MonocularPrior, GivesDepthToAJointSeenByOneCamera) {
  MOCAP_REQUIRE_SHARED("eval/humaneva_i_videopose3d/humaneva_cameras.json");
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  const Clip c = reconstruct(db);
  // The hidden joints are not triangulated (one view), the others are.
  int hidden_triangulated = 0, tracked = 0;
  for (const auto& r : c.results) {
    if (r.people.empty() || r.people.front().id < 0) continue;
    ++tracked;
    for (const int j : kHidden) hidden_triangulated += r.body_of(0)[j].valid() ? 1 : 0;
    EXPECT_EQ(r.body_of(0)[index(Joint::left_wrist)].view_count(), 2);
  }
  ASSERT_GE(tracked, 20);
  EXPECT_EQ(hidden_triangulated, 0);

  MultiViewFitOptions options;
  options.cameras = c.rig;
  options.fit = multiview_fit_defaults();
  MonocularPrior prior(db);
  int with_prior = 0;
  const auto [without_mm, without_n] =
      hidden_error_mm(c, fit_multiview_sequence(inputs(c, nullptr, false, &with_prior), options));
  const auto [prior_mm, prior_n] =
      hidden_error_mm(c, fit_multiview_sequence(inputs(c, &prior, false, &with_prior), options));
  EXPECT_EQ(with_prior, tracked);  // every tracked frame got its prior
  const auto [flipped_mm, flipped_n] =
      hidden_error_mm(c, fit_multiview_sequence(inputs(c, &prior, true, &with_prior), options));
  ASSERT_EQ(without_n, tracked);
  ASSERT_EQ(prior_n, tracked);
  ASSERT_EQ(flipped_n, tracked);
  std::cout << "right elbow and wrist seen by C1 only, mean error: no prior " << without_mm
            << " mm, monocular prior " << prior_mm << " mm, prior at the wrong depth " << flipped_mm
            << " mm\n";
  // Without a prior the arm's depth is a guess (30 cm off); the prior, retrieved from a small
  // database of three clips, puts it within 12 cm (96 mm measured).
  EXPECT_GT(without_mm, 200.0);
  EXPECT_LT(prior_mm, 120.0);
  EXPECT_LT(prior_mm, 0.4 * without_mm);
  // The prior decides: turned to the other depth, the arm follows it (the test can fail).
  EXPECT_GT(flipped_mm, prior_mm + 100.0);
}

TEST(MonocularPrior, IsStrongOnlyWhereViewsLackForARunOfFrames) {
  MOCAP_REQUIRE_SHARED("eval/humaneva_i_videopose3d/humaneva_cameras.json");
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  constexpr int kDropped = index(Joint::left_wrist);  // the left forearm's end
  constexpr std::size_t kDropFrame = 12;
  const Clip c = reconstruct(db, {kDropped, kDropFrame});
  ASSERT_FALSE(c.results[kDropFrame].people.empty());
  ASSERT_LT(c.results[kDropFrame].body_of(0)[kDropped].view_count(), 2);
  MonocularPrior prior(db);
  const auto& o = prior.options();
  ASSERT_GT(o.few_views_frames, 1);
  ASSERT_LT(static_cast<std::size_t>(o.few_views_frames), kFrames);
  const float strong = static_cast<float>(1.0 / o.few_views_rad);
  const float weak = static_cast<float>(1.0 / o.two_views_rad);
  constexpr int kForearm = kHidden[1];  // the right wrist's bone: C1 only, in every frame
  for (const bool live : {false, true}) {
    int with_prior = 0;
    std::vector<MultiViewFrameInput> track = inputs(c, &prior, false, &with_prior);
    ASSERT_GE(with_prior, 20);  // all but the frames before the track is confirmed
    // Per frame, both lack two views where they are hidden.
    EXPECT_FLOAT_EQ(track[kDropFrame].prior.inv_sigma[kDropped], strong);
    EXPECT_FLOAT_EQ(track[kDropFrame + 1].prior.inv_sigma[kDropped], weak);
    // A stream settles frame by frame, the past only: the same weights as live's.
    std::vector<MultiViewFrameInput> stream = track;
    MonocularPrior::Runs runs{};
    for (auto& frame : stream)
      prior.settle_newest(frame.prior.any() ? &frame.prior : nullptr, runs);
    prior.settle_runs(track, live);
    // One dropped frame: the neighbouring frames and C1 fix it; the weak weight.
    EXPECT_FLOAT_EQ(track[kDropFrame].prior.inv_sigma[kDropped], weak) << "live " << live;
    EXPECT_TRUE(track[kDropFrame].prior.few[kDropped]);  // the frame's own class is kept
    if (live) {
      for (std::size_t f = 0; f < kFrames; ++f)
        EXPECT_EQ(stream[f].prior.inv_sigma, track[f].prior.inv_sigma) << "frame " << f;
    }
    // Settling again gives the same weights.
    std::vector<MultiViewFrameInput> again = track;
    prior.settle_runs(again, live);
    for (std::size_t f = 0; f < kFrames; ++f)
      EXPECT_EQ(again[f].prior.inv_sigma, track[f].prior.inv_sigma);
    // Hidden from C2 for the whole second: strong, in live mode once the run is long enough.
    for (std::size_t f = 0; f < kFrames; ++f) {
      if (!track[f].prior.any()) continue;  // not tracked yet: counts as lacking views
      const bool strong_here = !live || f + 1 >= static_cast<std::size_t>(o.few_views_frames);
      EXPECT_FLOAT_EQ(track[f].prior.inv_sigma[kForearm], strong_here ? strong : weak)
          << "frame " << f << ", live " << live;
    }
  }
}

// The stream's fitter (multiview.reconstruct's fit) with and without a database, live: the mean
// error (mm) of the hidden joints over the frames it placed.
double stream_hidden_error_mm(const Clip& c, std::shared_ptr<const posedb::Database> db) {
  MultiViewPeopleFitOptions o;
  o.mode = StreamFitMode::live;
  o.fit.cameras = c.rig;
  o.fit.fit = multiview_fit_defaults();
  o.prior_db = std::move(db);
  MultiViewPeopleFitter fitter(o);
  const std::vector<People3D> out = test::fit_stream(fitter, c.input, c.results);
  double sum = 0.0;
  int n = 0;
  for (const People3D& frame : out)
    for (const Person3D& p : frame.people) {
      if (!p.placed) continue;
      const auto joints = joints_in_frame(p);
      for (const int j : kHidden)
        sum += glm::distance(joints[j], c.truth[static_cast<std::size_t>(frame.header.frame)][j]);
      n += 2;
    }
  EXPECT_GE(n, 2 * 20);
  return n > 0 ? 1000.0 * sum / n : NAN;
}

TEST(MonocularPrior, TheStreamFitTakesItWhenGivenADatabase) {
  MOCAP_REQUIRE_SHARED("eval/humaneva_i_videopose3d/humaneva_cameras.json");
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  auto db = std::make_shared<const posedb::Database>(posedb::Database::open(path));
  const Clip c = reconstruct(*db);
  const double without_mm = stream_hidden_error_mm(c, nullptr);
  const double prior_mm = stream_hidden_error_mm(c, db);
  std::cout << "stream, live: right elbow and wrist seen by C1 only: no database " << without_mm
            << " mm, with one " << prior_mm << " mm\n";
  // Runs counted from the past: the first few_views_frames - 1 frames are weak, the rest strong.
  EXPECT_GT(without_mm, 200.0);
  EXPECT_LT(prior_mm, 0.6 * without_mm);
}

TEST(MonocularPrior, WeighsABoneByHowWellTheViewsFixItsEnds) {
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  MonocularPrior prior(db);
  // Three cameras on a circle of 4 m around the origin, looking at it: 0 and 1 opposite (180
  // degrees), 2 at 90 degrees from both.
  std::vector<camera::Camera> rig(3);
  const double angles[] = {0.0, M_PI, 0.5 * M_PI};
  for (int i = 0; i < 3; ++i) {
    const glm::dvec3 centre(4.0 * std::cos(angles[i]), 1.0, 4.0 * std::sin(angles[i]));
    const glm::dvec3 forward = glm::normalize(glm::dvec3(0.0, 1.0, 0.0) - centre);
    const glm::dvec3 down(0.0, -1.0, 0.0);
    const glm::dvec3 right = glm::normalize(glm::cross(down, forward));
    rig[i].set_pose_from_centre(glm::dmat3(right, glm::cross(forward, right), forward), centre);
  }
  auto point = [](std::uint64_t views, float error_m) {
    multiview::TriangulatedPoint p;
    p.position = glm::vec3(0.0f, 1.0f, 0.0f);
    p.views = views;
    p.error_m = error_m;
    return p;
  };
  const auto& o = prior.options();
  const auto good3 = point(0b111, 0.01f), good2 = point(0b101, 0.01f);
  EXPECT_DOUBLE_EQ(prior.bone_weight(good3, good3, rig), 1.0 / o.many_views_rad);
  EXPECT_DOUBLE_EQ(prior.bone_weight(good3, good2, rig), 1.0 / o.two_views_rad);
  EXPECT_DOUBLE_EQ(prior.bone_weight(good3, point(0b011, 0.01f), rig), 1.0 / o.few_views_rad)
      << "two facing cameras do not see depth along their axis";
  EXPECT_DOUBLE_EQ(prior.bone_weight(good3, point(0b011, 0.0f), rig), 1.0 / o.two_views_rad)
      << "unless their keypoints are exact";
  EXPECT_DOUBLE_EQ(prior.bone_weight(good3, point(0b100, 0.01f), rig), 1.0 / o.few_views_rad);
  EXPECT_DOUBLE_EQ(prior.bone_weight(point(0, NAN), good3, rig), 1.0 / o.few_views_rad);
  EXPECT_DOUBLE_EQ(prior.bone_weight(good3, point(0b111, 0.5f), rig), 1.0 / o.few_views_rad)
      << "views that disagree";
}

}  // namespace
}  // namespace mocap::fit
