#include "eval/humaneva_protocol.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "posedb/database.hpp"
#include "support/shared_data.hpp"

namespace mocap::eval {
namespace {

namespace he = io::humaneva;

const char* const kFolder = "eval/humaneva_i_videopose3d";

TEST(HumanEvaProtocol, AxisConversionIsARotationThatPutsZUpOnY) {
  const glm::mat3 m = humaneva_world_to_y_up();
  EXPECT_FLOAT_EQ(glm::determinant(m), 1.0f);  // not a mirror
  const glm::mat3 identity = glm::transpose(m) * m;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) EXPECT_FLOAT_EQ(identity[c][r], c == r ? 1.0f : 0.0f);
  const glm::vec3 up = m * glm::vec3(0, 0, 1);
  EXPECT_FLOAT_EQ(up.y, 1.0f);
}

TEST(HumanEvaProtocol, EveryJointIsNamedInTheCorrespondence) {
  const auto lines = humaneva_joint_correspondence();
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(kBodyJoints));
  EXPECT_EQ(lines[index(Joint::root)], "root = HumanEva pelvis (pelvis (torsoDistal))");
  EXPECT_EQ(lines[index(Joint::head)], "head = HumanEva head (headDistal)");
  EXPECT_EQ(lines[index(Joint::left_knee)], "left_knee = HumanEva left_knee");
}

TEST(HumanEvaProtocol, TableMeansCellsAndSumsFrames) {
  HumanEvaTable table;
  Scores a, b;
  a.frames = a.valid = 2;
  a.pa_mpjpe_sum = 20;  // 10 mm
  b.frames = b.valid = 6;
  b.pa_mpjpe_sum = 180;  // 30 mm
  camera::Camera c1;
  c1.name = "C1";
  table.add({"S1", "Walk", "", c1, {}, {}}, a);
  table.add({"S2", "Box", "", c1, {}, {}}, b);
  EXPECT_DOUBLE_EQ(table.cell("S1", "Walk").pa_mpjpe(), 10.0);
  EXPECT_DOUBLE_EQ(table.mean_cell_pa_mpjpe(), 20.0);  // cells count once each
  EXPECT_DOUBLE_EQ(table.all().pa_mpjpe(), 25.0);      // every frame counts once
  EXPECT_EQ(table.cell("S3", "Jog").frames, 0.0);
}

// ---- the shared HumanEva-I files ----------------------------------------------------------------

class HumanEvaProtocolShared : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto folder = test::shared_data() / kFolder;
    if (!std::filesystem::exists(folder / he::kPositions2dFile)) return;
    data_ = std::make_unique<he::Dataset>(he::load_dataset(folder));
    cameras_ = std::make_unique<HumanEvaCameras>(he::load_cameras(folder / he::kCamerasFile));
  }
  static void TearDownTestSuite() {
    data_.reset();
    cameras_.reset();
  }
  void SetUp() override {
    MOCAP_REQUIRE_SHARED(std::string(kFolder) + "/" + std::string(he::kPositions2dFile));
  }
  static inline std::unique_ptr<he::Dataset> data_;
  static inline std::unique_ptr<HumanEvaCameras> cameras_;
};

TEST_F(HumanEvaProtocolShared, TrainMotionStandsUpWithItsLeftOnTheLeft) {
  const auto motion = humaneva_body_sequences(*data_, he::Split::train, {"Walking"});
  ASSERT_EQ(motion.size(), 4u);  // S1 chunk0, S2 chunk0, S3 chunk0 and chunk2
  const auto& s1 = motion.front();
  EXPECT_EQ(s1.name, "Train/S1 Walking 1 chunk0");
  EXPECT_EQ(s1.fps, 60.0);
  double facing_agreement = 0.0;
  for (std::size_t f = 1; f + 1 < s1.frames.size(); ++f) {
    const auto& b = s1.frames[f];
    EXPECT_GT(b[index(Joint::head)].y, b[index(Joint::root)].y + 0.5f) << f;
    // Walking forwards: the left side is up × forward (+X when facing +Z, y up).
    glm::vec3 forward = s1.frames[f + 1][index(Joint::root)] - s1.frames[f - 1][index(Joint::root)];
    forward.y = 0.0f;
    const glm::vec3 left = glm::normalize(glm::cross(glm::vec3(0, 1, 0), forward));
    const glm::vec3 across = glm::normalize(b[index(Joint::left_hip)] - b[index(Joint::right_hip)]);
    facing_agreement += glm::dot(left, across);
  }
  EXPECT_GT(facing_agreement / static_cast<double>(s1.frames.size() - 2), 0.9);
}

TEST_F(HumanEvaProtocolShared, ValidationInputAndTruthAgreeAtTheEvaluationRate) {
  const auto sequences = humaneva_validation_sequences(*data_, *cameras_, 24.0);
  std::size_t chunks = 0;
  for (const auto s : kHumanEvaSubjects)
    for (const auto& a : kHumanEvaActions)
      chunks += data_->select(he::Split::validate, s, a.data_name).size();
  ASSERT_EQ(sequences.size(), 3 * chunks);
  const auto& first = sequences.front();
  EXPECT_EQ(first.subject, "S1");
  EXPECT_EQ(first.action, "Walk");
  EXPECT_EQ(first.camera.name, "C1");
  const he::Chunk* chunk = data_->select(he::Split::validate, "S1", "Walking").front();
  EXPECT_EQ(first.input.size(), static_cast<std::size_t>((chunk->frames() - 1) / 2.5) + 1);
  ASSERT_EQ(first.input.size(), first.truth_camera.size());
  // The truth projected with the fitted intrinsics lands on the 2D input (the README's residual
  // is about a pixel; interpolation and distortion stay well under 10).
  const camera::Camera& camera = cameras_->at("S1").cameras.at(0);
  std::vector<double> residuals;
  for (std::size_t t = 0; t < first.input.size(); ++t) {
    for (int j = 0; j < kBodyJoints; ++j) {
      const glm::vec3 p = first.truth_camera[t][j];
      ASSERT_GT(p.z, 1.0f);  // in front of the camera
      const double u = camera.fx * p.x / p.z + camera.cx, v = camera.fy * p.y / p.z + camera.cy;
      residuals.push_back(std::hypot(u - first.input[t][3 * j], v - first.input[t][3 * j + 1]));
      EXPECT_EQ(first.input[t][3 * j + 2], 1.0f);
    }
  }
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  EXPECT_LT(residuals[residuals.size() / 2], 10.0);
}

TEST_F(HumanEvaProtocolShared, ReconstructsAShortSequenceWithATinyDatabase) {
  posedb::BuildOptions options;
  options.views.yaw_steps = 12;
  options.views.heights_m = {1.5f, 2.5f};
  options.clusters = 16;
  options.threads = 1;
  posedb::BuildReport report;
  test::TempDir dir;
  posedb::write_database(
      posedb::build_database_from_bodies(
          humaneva_body_sequences(*data_, he::Split::train, {"Walking"}), options, {}, report),
      dir.file("tiny.mdb"));
  const posedb::Database db = posedb::Database::open(dir.file("tiny.mdb"));
  const recon::FrameBones bones(db);
  recon::Matcher matcher(db, {});

  const auto sequences = humaneva_validation_sequences(*data_, *cameras_, db.build_info().fps);
  // The first chunk long enough (Validate/S1 Walking chunk0 has 13 frames at 60 Hz).
  const auto long_enough = std::find_if(sequences.begin(), sequences.end(),
                                        [](const auto& s) { return s.input.size() >= 40; });
  ASSERT_NE(long_enough, sequences.end());
  HumanEvaSequence sequence = *long_enough;
  sequence.input.resize(40);
  sequence.truth_camera.resize(40);
  const Scores scores =
      evaluate_sequence(matcher, bones, sequence, {0.02f, 0.0f}, recon::SequenceOptions{}, 7);
  EXPECT_EQ(scores.frames, 40.0);
  EXPECT_EQ(scores.valid, 40.0);
  EXPECT_TRUE(std::isfinite(scores.mpjpe()));
  EXPECT_TRUE(std::isfinite(scores.pa_mpjpe()));
  EXPECT_TRUE(std::isfinite(scores.accel()));
  EXPECT_LE(scores.pa_mpjpe(), scores.mpjpe());
  EXPECT_LT(scores.mpjpe(), 250.0);  // walking matched against walking: a sane error
}

}  // namespace
}  // namespace mocap::eval
