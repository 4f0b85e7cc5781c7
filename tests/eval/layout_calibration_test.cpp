#include "eval/layout_calibration.hpp"

#include <random>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "camera/rig_file.hpp"
#include "core/input_error.hpp"
#include "support/shared_data.hpp"

namespace mocap::eval {
namespace {

using recon::OffsetBasis;

Joints3 random_body(std::mt19937& rng) {
  std::uniform_real_distribution<float> jitter(-0.05f, 0.05f), angle(-3.1f, 3.1f);
  Joints3 b;
  const glm::vec3 base[kBodyJoints] = {
      {0, 1.75f, 0.02f},    {0, 1.52f, 0},        {-0.18f, 1.5f, 0}, {-0.25f, 1.2f, 0.1f},
      {-0.3f, 0.95f, 0.2f}, {0.18f, 1.5f, 0},     {0.25f, 1.2f, 0},  {0.3f, 0.95f, 0.1f},
      {-0.09f, 1.0f, 0},    {-0.1f, 0.55f, 0.1f}, {-0.1f, 0.1f, 0},  {0.09f, 1.0f, 0},
      {0.1f, 0.55f, 0},     {0.1f, 0.1f, 0},      {0, 1.0f, 0}};
  const glm::quat q = glm::angleAxis(angle(rng), glm::vec3(0, 1, 0)) *
                      glm::angleAxis(0.3f * angle(rng), glm::vec3(1, 0, 0));
  for (int j = 0; j < kBodyJoints; ++j)
    b[j] = q * (base[j] + glm::vec3(jitter(rng), jitter(rng), jitter(rng)));
  return b;
}

// Frames made with known coefficients give them back.
TEST(LayoutCalibration, FitRecoversKnownOffsets) {
  recon::LayoutOffsets truth;
  truth.layout = LayoutId::body25b;
  truth.joints[index(Joint::neck)] = {OffsetBasis::shoulders, -0.03f, 0.01f, -0.05f};
  truth.joints[index(Joint::left_hip)] = {OffsetBasis::hips, -0.05f, -0.04f, -0.06f};
  truth.joints[index(Joint::right_elbow)] = {OffsetBasis::bone, 0.09f, 0.0f, 0.0f};
  std::mt19937 rng(5);
  std::vector<CalibrationFrame> frames;
  for (int i = 0; i < 50; ++i) {
    CalibrationFrame f;
    f.keypoints = random_body(rng);
    f.reference = f.keypoints;
    recon::apply_layout_offsets_3d(truth, f.reference);
    frames.push_back(f);
  }
  const LayoutFit fit =
      fit_layout_offsets(LayoutId::body25b, frames, default_bases(LayoutId::body25b));
  for (int j = 0; j < kBodyJoints; ++j) {
    EXPECT_NEAR(fit.offsets.joints[j].along, truth.joints[j].along, 1e-4) << kJointNames[j];
    EXPECT_NEAR(fit.offsets.joints[j].lateral, truth.joints[j].lateral, 1e-4) << kJointNames[j];
    EXPECT_NEAR(fit.offsets.joints[j].forward, truth.joints[j].forward, 1e-4) << kJointNames[j];
    EXPECT_LT(fit.joints[j].after_3d_mm, 0.05) << kJointNames[j];
  }
  EXPECT_GT(fit.joints[index(Joint::neck)].before_mm, 10.0);
}

TEST(LayoutCalibration, Pose2SimBody25bLandsCloserToTheJointCentres) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/calibration/Calib_qualisys.toml");
  const auto dir = test::shared_data() / "eval/pose2sim_demo";
  const auto trc = io::read_trc(dir /
                                "S00_P00_T01_BalancingTrial/pose-3d/"
                                "S00_P00_T01_BalancingTrial_0-100_filt_butterworth_LSTM.trc");
  const auto frames = pose2sim_frames(trc, LayoutId::body25b);
  ASSERT_EQ(frames.size(), 100u);
  const LayoutFit fit =
      fit_layout_offsets(LayoutId::body25b, frames, default_bases(LayoutId::body25b));
  const auto cameras = camera::read_rig(dir / "calibration/Calib_qualisys.toml").cameras;
  ASSERT_EQ(cameras.size(), 4u);
  const auto check = evaluate_offsets_2d(fit.offsets, frames, cameras);
  double before = 0, after = 0;
  for (const auto& j : check) {
    before += j.before_mm;
    after += j.after_mm;
  }
  EXPECT_LT(after, 0.9 * before);
  // The reference is anatomical: hip joint centres lie inside the body, below and medial to
  // the detector's hip keypoints.
  EXPECT_LT(fit.joints[index(Joint::right_hip)].mean_offset_mm.x, -10.0);
  // COCO-17 has no head (ears) in the 3D data: not estimated, said so.
  const LayoutFit coco = fit_layout_offsets(
      LayoutId::coco17, pose2sim_frames(trc, LayoutId::coco17), default_bases(LayoutId::coco17));
  EXPECT_EQ(coco.offsets.joints[index(Joint::head)].basis, OffsetBasis::none);
  EXPECT_NE(coco.notes.find("head"), std::string::npos);
}

TEST(LayoutCalibration, Pose2SimCamerasRejectTruncation) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/calibration/Calib_qualisys.toml");
  const std::string text = test::read_file(
      (test::shared_data() / "eval/pose2sim_demo/calibration/Calib_qualisys.toml").string());
  const test::TempDir dir;
  const std::string file = dir.file("cut.toml");
  test::write_file(file, text.substr(0, text.find("rotation")));
  try {
    camera::read_rig(file);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
  }
}

TEST(LayoutCalibration, HumanEvaPelvisLiesBehindTheHipMidpoint) {
  MOCAP_REQUIRE_SHARED("eval/humaneva_i_videopose3d/data_3d_humaneva15.npz");
  io::humaneva::LoadOptions options;
  options.load_2d = false;
  const auto data =
      io::humaneva::load_dataset(test::shared_data() / "eval/humaneva_i_videopose3d", options);
  const auto train = humaneva_frames(data, io::humaneva::Split::train);
  const LayoutFit fit =
      fit_layout_offsets(LayoutId::humaneva15, train, default_bases(LayoutId::humaneva15));
  EXPECT_EQ(fit.offsets.joints[index(Joint::right_elbow)].basis, OffsetBasis::none);
  EXPECT_GT(fit.joints[index(Joint::root)].mean_offset_mm.z, 20.0);  // canonical root in front
  const auto held_out =
      evaluate_offsets_3d(fit.offsets, humaneva_frames(data, io::humaneva::Split::validate));
  for (Joint j : {Joint::head, Joint::neck, Joint::root})
    EXPECT_LT(held_out[index(j)].after_mm, held_out[index(j)].before_mm) << name(j);
}

}  // namespace
}  // namespace mocap::eval
