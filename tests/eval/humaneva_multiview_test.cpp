#include "eval/humaneva_multiview.hpp"

#include "eval/multiview_protocol.hpp"

#include <memory>

#include <gtest/gtest.h>

#include "support/shared_data.hpp"

namespace mocap::eval {
namespace {

namespace he = io::humaneva;

const char* const kFolder = "eval/humaneva_i_videopose3d";
constexpr std::size_t kFrames = 24;  // one second at the evaluation rate

TEST(HumanEvaMultiview, ScoresOnlyTheFramesKeptAndPlacedPosesAbsolutely) {
  std::vector<Body> truth(4);
  std::vector<recon::Pose3D> poses(4);
  for (std::size_t f = 0; f < 4; ++f) {
    for (int j = 0; j < kBodyJoints; ++j) {
      truth[f][j] = glm::vec3(0.1f * j, 0.05f * j * j, 3.0f);
      poses[f].joints[j] = truth[f][j] + glm::vec3(0.0f, 0.0f, 0.01f * (f + 1));  // shifted
    }
    poses[f].valid = f != 3;
  }
  const std::vector<char> keep = {1, 0, 1, 1};
  const TakeScores s = score_take(poses, truth, &keep, true);
  EXPECT_EQ(s.pose.valid, 2.0);            // frame 1 not kept, frame 3 not reconstructed
  EXPECT_NEAR(s.pose.mpjpe(), 0.0, 1e-3);  // a shift is gone once the roots coincide
  ASSERT_EQ(s.absolute_frames, 2);
  EXPECT_NEAR(1000.0 * s.absolute_m / 2, 20.0, 1e-3);  // (10 + 30) / 2 mm
  ASSERT_EQ(s.tracks.size(), 1u);
  EXPECT_EQ(s.tracks[0].reconstructed.size(), 4u);
  EXPECT_EQ(cameras_label(std::vector<int>{0, 2}), "C1+C3");
}

class HumanEvaMultiviewShared : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto folder = test::shared_data() / kFolder;
    if (!std::filesystem::exists(folder / he::kPositions2dFile)) return;
    const he::Dataset data = he::load_dataset(folder);
    const auto cameras = he::load_cameras(folder / he::kCamerasFile);
    auto all = humaneva_validation_sequences(data, cameras, 24.0);
    // The three cameras of the first chunk that lasts a second, shortened to that second.
    std::size_t first = 0;
    while (first + 3 <= all.size() && all[first].input.size() < kFrames) first += 3;
    ASSERT_LE(first + 3, all.size()) << "no Validate chunk of " << kFrames << " frames";
    sequences_ = std::make_unique<std::vector<HumanEvaSequence>>(all.begin() + first,
                                                                 all.begin() + first + 3);
    for (HumanEvaSequence& s : *sequences_) {
      s.input.resize(kFrames);
      s.truth_camera.resize(kFrames);
    }
    takes_ = std::make_unique<std::vector<HumanEvaTake>>(humaneva_takes(*sequences_, cameras));
  }
  static void TearDownTestSuite() {
    sequences_.reset();
    takes_.reset();
  }
  void SetUp() override {
    MOCAP_REQUIRE_SHARED(std::string(kFolder) + "/" + std::string(he::kPositions2dFile));
  }

  static TakeReconstruction reconstruct(const std::vector<int>& cameras, bool fit) {
    const std::vector<recon::BodyXyc> inputs[] = {(*sequences_)[0].input, (*sequences_)[1].input,
                                                  (*sequences_)[2].input};
    HumanEvaMultiviewOptions options;
    options.fit = fit;
    return reconstruct_take(takes_->front(), *sequences_, inputs, cameras, options);
  }
  // Mean absolute joint error (mm, world, no alignment) of the triangulation from `cameras` at
  // σ 0, and its coverage.
  static std::pair<double, double> error_mm(const std::vector<int>& cameras) {
    const TakeReconstruction r = reconstruct(cameras, false);
    EXPECT_EQ(r.extra_people, 0);
    const TakeScores s = score_take(r.triangulated, takes_->front().truth_world, nullptr, true);
    return {1000.0 * s.absolute_m / static_cast<double>(s.absolute_frames), s.pose.coverage()};
  }

  static inline std::unique_ptr<std::vector<HumanEvaSequence>> sequences_;
  static inline std::unique_ptr<std::vector<HumanEvaTake>> takes_;
};

TEST_F(HumanEvaMultiviewShared, TakesAreChunksSeenByTheThreeCamerasInTheWorld) {
  ASSERT_EQ(takes_->size(), 1u);
  EXPECT_EQ(sequences_->front().subject + " " + sequences_->front().chunk, "S1 Walking 1 chunk2");
  const HumanEvaTake& take = takes_->front();
  ASSERT_EQ(take.truth_world.size(), kFrames);
  // HumanEva's world is Z up with the floor at Z = 0: the head is well above the ankles.
  const Body& first = take.truth_world.front();
  EXPECT_GT(first[index(Joint::head)].z, 1.3f);
  EXPECT_LT(first[index(Joint::right_ankle)].z, 0.3f);
  EXPECT_DOUBLE_EQ(take.floor.normal.z, 1.0);
}

TEST_F(HumanEvaMultiviewShared, ThreeCamerasReconstructTheTruthAndTwoDoNoBetter) {
  const auto [three, coverage] = error_mm({0, 1, 2});
  // The 2D is the truth projected through HumanEva's own calibration; ours is a pinhole fitted
  // to it without distortion (0.7-1.3 px median residual, README of the data), a few mm at 4 m.
  EXPECT_LT(three, 10.0);
  // Every frame but a track's first ones (TrackingOptions::min_hits) is reported.
  EXPECT_GE(coverage, (kFrames - 2.0) / kFrames);
  // Measured (S1 "Walking 1 chunk2"): 8.5 mm with all three; C1+C2 9.5, C1+C3 9.2, C2+C3 15.9 (C2
  // and C3 face each other, 176 degrees apart: depth along their common axis is poorly seen).
  for (const auto& pair : {std::vector<int>{0, 1}, {0, 2}, {1, 2}}) {
    const auto [two, pair_coverage] = error_mm(pair);
    EXPECT_GE(two, three) << cameras_label(pair);
    EXPECT_LT(two, 25.0) << cameras_label(pair);
    EXPECT_GE(pair_coverage, (kFrames - 2.0) / kFrames) << cameras_label(pair);
  }
}

TEST_F(HumanEvaMultiviewShared, TheFitKeepsOneSkeletonNearTheTruth) {
  const TakeReconstruction r = reconstruct({0, 1, 2}, true);
  ASSERT_EQ(r.fitted.size(), kFrames);
  TakeScores s = score_take(r.fitted, takes_->front().truth_world, nullptr, true);
  ASSERT_GT(s.absolute_frames, 0);
  EXPECT_LT(1000.0 * s.absolute_m / static_cast<double>(s.absolute_frames), 25.0);
  MultiviewResult bones;
  add_track_metrics(s.tracks, bones);
  EXPECT_LT(bones.bone_std_mm, 0.1);  // one set of bone lengths for the whole take
  EXPECT_GT(bones.truth_bone_std_mm, bones.bone_std_mm);
}

}  // namespace
}  // namespace mocap::eval
