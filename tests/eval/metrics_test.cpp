#include "eval/metrics.hpp"

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

namespace mocap::eval {
namespace {

using Pose15 = std::array<glm::vec3, kBodyJoints>;

Pose15 random_pose(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-0.8f, 0.8f);
  Pose15 p;
  for (auto& j : p) j = {u(rng), u(rng), u(rng) + 3.0f};
  return p;
}

Pose15 transformed(const Pose15& pose, float angle, glm::vec3 axis, float scale, glm::vec3 shift) {
  const glm::mat3 r(glm::rotate(glm::mat4(1.0f), angle, glm::normalize(axis)));
  Pose15 out;
  for (int j = 0; j < kBodyJoints; ++j) out[j] = scale * (r * pose[j]) + shift;
  return out;
}

// Three joints, root first: the hand examples below use MetricOptions{0}.
const MetricOptions kRootFirst{0, false};

TEST(Metrics, IdenticalPosesHaveZeroError) {
  std::mt19937 rng(1);
  const Pose15 p = random_pose(rng);
  for (Metric m : {Metric::mpjpe, Metric::pa_mpjpe, Metric::n_mpjpe}) {
    const JointErrors e = frame_errors(m, p, p);
    EXPECT_NEAR(e.mean_mm, 0.0, 1e-3);
    ASSERT_EQ(e.per_joint_mm.size(), 15u);
  }
}

TEST(Metrics, SimilarityCopyHasZeroPaMpjpeButNotMpjpe) {
  std::mt19937 rng(2);
  const Pose15 truth = random_pose(rng);
  const Pose15 copy = transformed(truth, 0.7f, {0.2f, 1.0f, -0.3f}, 1.3f, {0.4f, -0.1f, 2.0f});
  EXPECT_NEAR(pa_mpjpe(copy, truth).mean_mm, 0.0, 1e-3);
  EXPECT_GT(mpjpe(copy, truth).mean_mm, 100.0);
  EXPECT_GT(n_mpjpe(copy, truth).mean_mm, 100.0);
  // A translated and scaled copy: MPJPE sees the scale, N-MPJPE does not.
  const Pose15 scaled = transformed(truth, 0.0f, {0, 1, 0}, 0.8f, {1.0f, 2.0f, 3.0f});
  EXPECT_NEAR(n_mpjpe(scaled, truth).mean_mm, 0.0, 1e-3);
  EXPECT_GT(mpjpe(scaled, truth).mean_mm, 10.0);
}

// Root-relative prediction (0.1, 0, 0), (0, 0.2, 0); truth (0.1, 0, 0), (0, 0, 0.2):
// errors 0 and |(0, 0.2, -0.2)| = 0.2828427 m.
TEST(Metrics, MpjpeByHand) {
  const std::vector<glm::vec3> prediction = {{1, 1, 1}, {1.1f, 1, 1}, {1, 1.2f, 1}};
  const std::vector<glm::vec3> truth = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0, 0.2f}};
  const JointErrors e = mpjpe(prediction, truth, kRootFirst);
  EXPECT_NEAR(e.per_joint_mm[0], 0.0, 1e-9);
  EXPECT_NEAR(e.per_joint_mm[1], 0.0, 1e-3);
  EXPECT_NEAR(e.per_joint_mm[2], 282.8427, 1e-3);
  EXPECT_NEAR(e.mean_mm, 141.4214, 1e-3);  // the root is not averaged
  EXPECT_NEAR(mpjpe(prediction, truth, {0, true}).mean_mm, 94.2809, 1e-3);
}

// Root-relative prediction (0.1, 0, 0), (0, 0.2, 0); truth (0.1, 0, 0), (0, 0.1, 0):
// s = (0.01 + 0.02) / (0.01 + 0.04) = 0.6; scaled (0.06, 0, 0), (0, 0.12, 0): errors 40, 20 mm.
TEST(Metrics, NMpjpeByHand) {
  const std::vector<glm::vec3> prediction = {{0, 0, 5}, {0.1f, 0, 5}, {0, 0.2f, 5}};
  const std::vector<glm::vec3> truth = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}};
  const JointErrors e = n_mpjpe(prediction, truth, kRootFirst);
  EXPECT_NEAR(e.per_joint_mm[1], 40.0, 1e-3);
  EXPECT_NEAR(e.per_joint_mm[2], 20.0, 1e-3);
  EXPECT_NEAR(e.mean_mm, 30.0, 1e-3);
}

// The mirror case of procrustes_test.cpp as a pose: ±0.3 x, ±0.2 y, ±0.1 z against its image
// under x → −x. Residuals 3/70, 3/70, 2/70, 2/70, 13/70, 13/70 m: mean 6/70 m over all six
// joints (VideoPose3D's p_mpjpe), 33/350 m without the root (joint 0).
TEST(Metrics, PaMpjpeOfAMirrorImageByHand) {
  const std::vector<glm::vec3> prediction = {{0.3f, 0, 0},  {-0.3f, 0, 0}, {0, 0.2f, 0},
                                             {0, -0.2f, 0}, {0, 0, 0.1f},  {0, 0, -0.1f}};
  std::vector<glm::vec3> truth;
  for (const auto& p : prediction) truth.push_back({-p.x, p.y, p.z});
  EXPECT_NEAR(pa_mpjpe(prediction, truth, {0, true}).mean_mm, 6000.0 / 70.0, 1e-3);
  const JointErrors e = pa_mpjpe(prediction, truth, kRootFirst);
  EXPECT_NEAR(e.mean_mm, 33000.0 / 350.0, 1e-3);
  EXPECT_NEAR(e.per_joint_mm[4], 13000.0 / 70.0, 1e-3);
  // MPJPE (root 0 at +0.3 x): root-relative prediction vs truth differ by a mirror and a shift.
  EXPECT_GT(mpjpe(prediction, truth, kRootFirst).mean_mm, e.mean_mm);
}

TEST(Metrics, BadInputThrows) {
  const std::vector<glm::vec3> three(3, glm::vec3(0.0f)), two(2, glm::vec3(0.0f));
  EXPECT_THROW(mpjpe(three, two, kRootFirst), std::invalid_argument);
  std::vector<glm::vec3> nan = three;
  nan[1].y = std::nanf("");
  EXPECT_THROW(pa_mpjpe(nan, three, kRootFirst), std::invalid_argument);
  EXPECT_THROW(mpjpe(three, three), std::invalid_argument);  // Body15 root 14 is outside
  const std::vector<glm::vec3> one(1, glm::vec3(0.0f));
  EXPECT_THROW(mpjpe(one, one, kRootFirst), std::invalid_argument);  // nothing to average
}

// Two joints: the root at the origin and one joint on the x axis.
std::vector<std::vector<glm::vec3>> track(const std::vector<float>& xs,
                                          glm::vec3 root_acceleration = {}) {
  std::vector<std::vector<glm::vec3>> frames;
  for (std::size_t t = 0; t < xs.size(); ++t) {
    const glm::vec3 root = static_cast<float>(t * t) * root_acceleration;
    frames.push_back({root, root + glm::vec3(xs[t], 0, 0)});
  }
  return frames;
}

TEST(Metrics, AccelerationOfConstantVelocityIsZero) {
  const auto truth = track({0.0f, 0.01f, 0.02f, 0.03f, 0.04f});
  const auto views = frame_views(truth);
  EXPECT_NEAR(jitter(views, kRootFirst).mean_mm(), 0.0, 1e-4);
  EXPECT_EQ(jitter(views, kRootFirst).frames(), 3u);
  // An accelerating root moves every joint alike: root-relative accelerations stay zero.
  const auto carried = track({0.0f, 0.01f, 0.02f, 0.03f, 0.04f}, {0.05f, 0.0f, 0.02f});
  const auto carried_views = frame_views(carried);
  EXPECT_NEAR(acceleration_errors(carried_views, views, kRootFirst).mean_mm(), 0.0, 1e-4);
}

// x = t² mm: a = 2 mm/frame² at every inner frame; the truth moves at constant velocity.
TEST(Metrics, AccelerationErrorAndJitterByHand) {
  const auto prediction = track({0.0f, 0.001f, 0.004f, 0.009f});
  const auto truth = track({0.0f, 0.001f, 0.002f, 0.003f});
  const auto p = frame_views(prediction), t = frame_views(truth);
  const ErrorAccumulator e = acceleration_errors(p, t, kRootFirst);
  EXPECT_EQ(e.frames(), 2u);
  EXPECT_NEAR(e.mean_mm(), 2.0, 1e-4);
  EXPECT_NEAR(e.per_joint_mean_mm()[1], 2.0, 1e-4);
  EXPECT_NEAR(e.per_joint_mean_mm()[0], 0.0, 1e-9);
  EXPECT_NEAR(jitter(p, kRootFirst).mean_mm(), 2.0, 1e-4);
  EXPECT_EQ(jitter(std::span(p).first(2), kRootFirst).frames(), 0u);  // needs three frames
  EXPECT_THROW(acceleration_errors(p, std::span(t).first(3), kRootFirst), std::invalid_argument);
}

TEST(Metrics, SequenceErrorsAverageFrames) {
  std::mt19937 rng(4);
  std::vector<Pose15> truth, prediction;
  for (int t = 0; t < 5; ++t) {
    truth.push_back(random_pose(rng));
    prediction.push_back(truth.back());
    prediction.back()[0].x += 0.01f * static_cast<float>(t);  // head off by 0, 10, ..., 40 mm
  }
  const auto e = sequence_errors(Metric::mpjpe, frame_views(prediction), frame_views(truth));
  EXPECT_EQ(e.frames(), 5u);
  EXPECT_NEAR(e.per_joint_mean_mm()[0], 20.0, 1e-3);
  EXPECT_NEAR(e.mean_mm(), 20.0 / 14.0, 1e-3);
}

TEST(Accumulators, MergeAndWeights) {
  ErrorAccumulator a, b;
  a.add({{0.0, 2.0}, 2.0});
  b.add({{0.0, 4.0}, 4.0});
  b.add({{0.0, 6.0}, 6.0});
  a.merge(b);
  EXPECT_EQ(a.frames(), 3u);
  EXPECT_DOUBLE_EQ(a.mean_mm(), 4.0);
  EXPECT_DOUBLE_EQ(a.per_joint_mean_mm()[1], 4.0);
  EXPECT_TRUE(std::isnan(ErrorAccumulator().mean_mm()));
  EXPECT_THROW(a.add({{1.0}, 1.0}), std::invalid_argument);

  MeanAccumulator per_sequence, per_frame;
  per_sequence.add(10.0);
  per_sequence.add(20.0);
  per_frame.add(10.0, 100.0);  // sequence means weighted by their frame counts
  per_frame.add(20.0, 300.0);
  EXPECT_DOUBLE_EQ(per_sequence.mean(), 15.0);
  EXPECT_DOUBLE_EQ(per_frame.mean(), 17.5);
  per_sequence.merge(per_frame);
  EXPECT_EQ(per_sequence.count(), 4u);
  EXPECT_TRUE(std::isnan(MeanAccumulator().mean()));
  EXPECT_THROW(per_frame.add(1.0, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace mocap::eval
