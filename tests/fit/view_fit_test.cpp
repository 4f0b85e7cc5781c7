// End to end on a few frames of the real multi-view data: each calibrated view reconstructed and
// fitted on its own (fit/view_fit.hpp), the views compared in the world (eval/crossview.hpp).

#include "fit/view_fit.hpp"

#include <cmath>
#include <optional>

#include <gtest/gtest.h>
#include <glm/gtc/quaternion.hpp>
#include <glm/matrix.hpp>

#include "eval/crossview.hpp"
#include "eval/humaneva_protocol.hpp"
#include "eval/pose2sim_trial.hpp"
#include "fit/fit_evaluation.hpp"
#include "posedb/database.hpp"
#include "support/small_pose_database.hpp"

namespace mocap::fit {
namespace {

constexpr glm::dvec3 kUp{0.0, 0.0, 1.0};

struct View {
  std::vector<recon::BodyXyc> input;
  std::vector<eval::Body> truth_camera;
  camera::Camera camera;  // calibrated: the retrieval's and the fit's, placed in the world
};

struct Outcome {
  std::vector<ViewFits> fits;
  double truth_cm = 0, retrieval_cm = 0, fit_cm = 0, fit_mpjpe = 0;
};

Outcome run(const posedb::Database& db, const std::vector<View>& views) {
  const recon::FrameBones bones(db);
  const ContactDetector contacts(db);
  Outcome out;
  std::vector<std::vector<std::optional<eval::Body>>> truth, retrieval, fitted;
  eval::Scores scores;
  for (const View& v : views) {
    recon::Matcher matcher(db, {});
    recon::SequenceOptions retrieval_options;
    retrieval_options.fps = db.build_info().fps;
    retrieval_options.selection = recon::Selection::path;
    retrieval_options.smoothing = recon::Smoothing::savitzky_golay;
    retrieval_options.camera = v.camera;
    FitOptions options;
    options.camera = v.camera;
    options.ground = GroundPlane{kUp, 0.0};
    out.fits.push_back(reconstruct_and_fit(matcher, bones, &contacts, v.input, retrieval_options,
                                           options, {true, true}));
    const ViewFits& f = out.fits.back();
    EXPECT_EQ(f.retrieved.size(), v.input.size());
    EXPECT_EQ(f.full.size(), v.input.size());
    EXPECT_EQ(f.live.size(), v.input.size());
    const glm::dmat3 to_world = glm::transpose(v.camera.rotation);
    auto &t = truth.emplace_back(), &r = retrieval.emplace_back(), &g = fitted.emplace_back();
    for (std::size_t i = 0; i < v.input.size(); ++i) {
      t.push_back(eval::to_world_root_relative(v.truth_camera[i], to_world));
      r.push_back(f.retrieved[i].valid
                      ? std::optional(eval::to_world_root_relative(f.retrieved[i].joints, to_world))
                      : std::nullopt);
      g.push_back(f.full[i].valid ? std::optional(eval::to_world_root_relative(
                                        f.full[i].root_relative(), to_world))
                                  : std::nullopt);
    }
    scores.add(eval::score(as_poses(f.full), v.truth_camera));
  }
  const auto none = eval::CrossViewAlignment::none;
  out.truth_cm = eval::mean_cm(eval::crossview_pairs(truth, kUp, none));
  out.retrieval_cm = eval::mean_cm(eval::crossview_pairs(retrieval, kUp, none));
  out.fit_cm = eval::mean_cm(eval::crossview_pairs(fitted, kUp, none));
  out.fit_mpjpe = scores.mpjpe();
  return out;
}

TEST(ViewFit, HumanEvaChunkSeenByItsThreeCameras) {
  MOCAP_REQUIRE_SHARED("eval/humaneva_i_videopose3d/humaneva_cameras.json");
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  const auto folder = test::shared_data() / "eval/humaneva_i_videopose3d";
  const auto data = io::humaneva::load_dataset(folder);
  const auto cameras = io::humaneva::load_cameras(folder / io::humaneva::kCamerasFile);
  const auto sequences = eval::humaneva_validation_sequences(data, cameras, db.build_info().fps);
  ASSERT_GE(sequences.size(), 3u);
  std::size_t first = 0;  // the first chunk with 24 frames at least; its C1, C2, C3 follow
  while (first + 3 <= sequences.size() && sequences[first].input.size() < 24) first += 3;
  ASSERT_LE(first + 3, sequences.size());
  std::vector<View> views;
  for (int c = 0; c < 3; ++c) {
    const auto& s = sequences[first + c];
    ASSERT_EQ(s.camera.name, cameras.at(s.subject).cameras.at(c).name);
    View v{s.input, s.truth_camera, s.camera};
    v.input.resize(24);
    v.truth_camera.resize(24);
    views.push_back(v);
  }
  const Outcome o = run(db, views);
  EXPECT_LT(o.truth_cm, 0.01);  // the truth agrees with itself through the three cameras
  EXPECT_TRUE(std::isfinite(o.retrieval_cm));
  EXPECT_GT(o.retrieval_cm, 0.5);
  EXPECT_LT(o.retrieval_cm, 60.0);
  EXPECT_LT(o.fit_cm, 60.0);
  // Loose bounds: the test database holds three clips (walk, run, bow), not HumanEva's motion.
  EXPECT_LT(o.fit_mpjpe, 400.0);
  // The fit places the person in front of the camera, within a few metres of the truth's depth
  // (monocular depth follows the database skeleton's size).
  const float depth = o.fits[0].full[12].root().z;
  const float truth_depth = views[0].truth_camera[12][index(Joint::root)].z;
  EXPECT_GT(depth, 0.5f * truth_depth);
  EXPECT_LT(depth, 3.0f * truth_depth);
}

TEST(ViewFit, Pose2SimBalancingTrialSeenByItsFourCameras) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/S00_P00_T01_BalancingTrial/pose-3d");
  MOCAP_REQUIRE_SMALL_DATABASE(path);
  const posedb::Database db = posedb::Database::open(path);
  const auto root = test::shared_data() / "eval/pose2sim_demo";
  const auto trial = eval::load_pose2sim_trial(root / "S00_P00_T01_BalancingTrial",
                                               root / "calibration/Calib_qualisys.toml", 40);
  const double fps = db.build_info().fps;
  std::vector<View> views;
  for (const auto& v : trial.views) {
    views.push_back({eval::resample_keypoints(v.input, trial.fps, fps),
                     eval::resample_bodies(v.truth_camera, trial.fps, fps), v.camera});
  }
  ASSERT_EQ(views.size(), 4u);
  EXPECT_EQ(views[0].input.size(), 16u);
  const Outcome o = run(db, views);
  EXPECT_LT(o.truth_cm, 0.01);
  EXPECT_TRUE(std::isfinite(o.retrieval_cm));
  EXPECT_LT(o.retrieval_cm, 60.0);
  EXPECT_LT(o.fit_cm, 60.0);
  EXPECT_LT(o.fit_mpjpe, 300.0);
}

}  // namespace
}  // namespace mocap::fit
