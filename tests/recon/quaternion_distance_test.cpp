// Rotation distances and bone rotations against values worked out by hand.

#include "recon/quaternion_distance.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/quaternion.hpp>

namespace mocap::recon {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

glm::quat about(float angle, glm::vec3 axis) { return glm::angleAxis(angle, glm::normalize(axis)); }

glm::quat random_rotation(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  glm::quat q(u(rng), u(rng), u(rng), u(rng));
  return glm::normalize(q);
}

TEST(QuaternionDistance, IsTheRotationAngle) {
  const glm::quat identity(1, 0, 0, 0);
  for (float angle : {0.0f, 0.3f, 1.0f, 2.0f, 3.0f}) {
    EXPECT_NEAR(quaternion_distance(identity, about(angle, {1, 2, 3})), angle, 1e-6f) << angle;
  }
  // Between two rotations about one axis: the difference of the angles.
  EXPECT_NEAR(quaternion_distance(about(0.4f, {0, 1, 0}), about(1.5f, {0, 1, 0})), 1.1f, 1e-6f);
  // Two quarter turns about perpendicular axes: q1⁻¹q2 has w = cos²(π/4) = 1/2, angle 2π/3.
  EXPECT_NEAR(quaternion_distance(about(kPi / 2, {1, 0, 0}), about(kPi / 2, {0, 1, 0})),
              2.0f * kPi / 3.0f, 1e-6f);
}

TEST(QuaternionDistance, SignInvariantAndSymmetric) {
  std::mt19937 rng(7);
  for (int i = 0; i < 100; ++i) {
    const glm::quat a = random_rotation(rng);
    const glm::quat b = random_rotation(rng);
    const float d = quaternion_distance(a, b);
    EXPECT_GE(d, 0.0f);
    EXPECT_LE(d, kPi);
    EXPECT_NEAR(quaternion_distance(a, -b), d, 1e-6f);
    EXPECT_NEAR(quaternion_distance(-a, b), d, 1e-6f);
    EXPECT_NEAR(quaternion_distance(b, a), d, 1e-6f);
  }
  const glm::quat q = about(1.0f, {1, 1, 0});
  EXPECT_NEAR(quaternion_distance(q, -q), 0.0f, 1e-7f);
}

// A metric on rotations: invariant when both are turned by the same rotation (on either side),
// and the triangle inequality holds.
TEST(QuaternionDistance, BiInvariantMetric) {
  std::mt19937 rng(11);
  for (int i = 0; i < 100; ++i) {
    const glm::quat a = random_rotation(rng);
    const glm::quat b = random_rotation(rng);
    const glm::quat c = random_rotation(rng);
    const glm::quat r = random_rotation(rng);
    const float d = quaternion_distance(a, b);
    EXPECT_NEAR(quaternion_distance(r * a, r * b), d, 2e-5f);
    EXPECT_NEAR(quaternion_distance(a * r, b * r), d, 2e-5f);
    EXPECT_LE(d, quaternion_distance(a, c) + quaternion_distance(c, b) + 1e-5f);
  }
}

// acos(|dot|) would be wrong by about 3e-4 rad near 0 in float; the atan2 form keeps the digits.
TEST(QuaternionDistance, AccurateNearZeroAndHalfTurn) {
  const glm::quat base = about(0.7f, {0, 0, 1});
  for (float small : {1e-3f, 1e-4f, 1e-5f}) {
    const float d = quaternion_distance(base, base * about(small, {1, 0, 0}));
    EXPECT_NEAR(d, small, small * 0.02f) << small;
  }
  const glm::quat identity(1, 0, 0, 0);
  EXPECT_NEAR(quaternion_distance(identity, about(kPi, {0, 1, 0})), kPi, 1e-6f);
  EXPECT_NEAR(quaternion_distance(identity, about(kPi - 1e-3f, {0, 1, 0})), kPi - 1e-3f, 1e-5f);
  // Just past a half turn the shorter way round is taken.
  EXPECT_NEAR(quaternion_distance(identity, about(kPi + 1e-3f, {0, 1, 0})), kPi - 1e-3f, 1e-5f);
}

TEST(QuaternionDistance, IgnoresScale) {
  const glm::quat a = about(0.5f, {1, 0, 0});
  const glm::quat b = about(1.3f, {0, 1, 1});
  EXPECT_NEAR(quaternion_distance(2.0f * a, 0.5f * b), quaternion_distance(a, b), 1e-6f);
}

TEST(PoseDistance, WeightedSumOfSquaredAngles) {
  const glm::quat identity(1, 0, 0, 0);
  const std::array<glm::quat, 3> a = {identity, identity, identity};
  const std::array<glm::quat, 3> b = {about(0.1f, {1, 0, 0}), about(0.2f, {0, 1, 0}),
                                      about(3.0f, {0, 0, 1})};
  const std::array<float, 3> weights = {1.0f, 2.0f, 0.0f};
  // 1 · 0.1² + 2 · 0.2² + 0 · 3² = 0.01 + 0.08 = 0.09.
  EXPECT_NEAR(pose_distance(a, b, weights), 0.09f, 1e-6f);
  EXPECT_NEAR(pose_distance(a, a, weights), 0.0f, 1e-9f);
  const std::array<float, 2> too_few = {1.0f, 1.0f};
  EXPECT_THROW(pose_distance(a, b, too_few), std::invalid_argument);
}

TEST(SwingRotation, TakesFromToToByTheSmallestRotation) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 200; ++i) {
    const glm::vec3 from(u(rng), u(rng), u(rng));
    const glm::vec3 to(u(rng), u(rng), u(rng));
    const glm::quat q = swing_rotation(from, 3.0f * to);
    EXPECT_NEAR(glm::length(q), 1.0f, 1e-5f);
    const glm::vec3 turned = q * glm::normalize(from);
    EXPECT_NEAR(glm::distance(turned, glm::normalize(to)), 0.0f, 1e-5f);
    // Smallest: its angle is the angle between the directions, its axis normal to both.
    const float between =
        std::acos(glm::clamp(glm::dot(glm::normalize(from), glm::normalize(to)), -1.0f, 1.0f));
    EXPECT_NEAR(quaternion_distance(glm::quat(1, 0, 0, 0), q), between, 1e-4f);
    EXPECT_NEAR(glm::dot(glm::vec3(q.x, q.y, q.z), from), 0.0f, 1e-5f);
  }
}

TEST(SwingRotation, HandWorkedCases) {
  // +X to +Y: a quarter turn about +Z.
  const glm::quat q = swing_rotation({1, 0, 0}, {0, 2, 0});
  EXPECT_NEAR(q.w, std::sqrt(0.5f), 1e-6f);
  EXPECT_NEAR(q.z, std::sqrt(0.5f), 1e-6f);
  EXPECT_NEAR(q.x, 0.0f, 1e-7f);
  EXPECT_NEAR(q.y, 0.0f, 1e-7f);
  // Opposite directions: half a turn about +Z for directions in the XY plane, about X for Z.
  const glm::quat flip = swing_rotation({0, -1, 0}, {0, 1, 0});
  EXPECT_NEAR(std::abs(flip.z), 1.0f, 1e-6f);
  const glm::quat flip_z = swing_rotation({0, 0, 1}, {0, 0, -1});
  EXPECT_NEAR(std::abs(flip_z.x), 1.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(flip_z * glm::vec3(0, 0, 1), glm::vec3(0, 0, -1)), 0.0f, 1e-6f);
  // Undefined directions give the identity.
  EXPECT_EQ(swing_rotation({0, 0, 0}, {1, 0, 0}), glm::quat(1, 0, 0, 0));
  EXPECT_EQ(swing_rotation({1, 0, 0}, {NAN, 0, 0}), glm::quat(1, 0, 0, 0));
}

// The rest pose of the header comment, 1 unit per bone, root at the origin.
std::array<glm::vec3, kBodyJoints> t_pose() {
  std::array<glm::vec3, kBodyJoints> joints{};
  joints[index(Joint::root)] = {0, 0, 0};
  for (int bone = 0; bone < kBodyBones; ++bone) {
    // A joint is the sum of the rest directions of the bones from the root down to it.
    glm::vec3 p(0.0f);
    for (int j = bone; j != index(Joint::root); j = kJointParent[j]) p += kBoneRestDirection[j];
    joints[bone] = p;
  }
  return joints;
}

TEST(BoneRotations, RestPoseIsIdentity) {
  const BoneRotations r = bone_rotations(t_pose());
  for (int b = 0; b < kBodyBones; ++b) {
    EXPECT_NEAR(quaternion_distance(r[b], glm::quat(1, 0, 0, 0)), 0.0f, 1e-6f) << kJointNames[b];
  }
}

TEST(BoneRotations, RaisedForearmIsAQuarterTurn) {
  std::array<glm::vec3, kBodyJoints> joints = t_pose();
  // Left forearm up: elbow → wrist along +Y instead of +X.
  joints[index(Joint::left_wrist)] = joints[index(Joint::left_elbow)] + glm::vec3(0, 0.8f, 0);
  const BoneRotations r = bone_rotations(joints);
  const glm::quat expected = about(kPi / 2, {0, 0, 1});
  EXPECT_NEAR(quaternion_distance(r[index(Joint::left_wrist)], expected), 0.0f, 1e-6f);
  for (int b = 0; b < kBodyBones; ++b) {
    if (b == index(Joint::left_wrist)) continue;
    EXPECT_NEAR(quaternion_distance(r[b], glm::quat(1, 0, 0, 0)), 0.0f, 1e-6f) << kJointNames[b];
  }
}

// A body turned about the vertical: limbs perpendicular to it take exactly that turn, the spine
// and legs (along it) none. Scale, i.e. the skeleton's size, does not matter.
TEST(BoneRotations, TurnedAndScaledBody) {
  const glm::quat turn = about(0.6f, {0, 1, 0});
  std::array<glm::vec3, kBodyJoints> joints = t_pose();
  for (glm::vec3& p : joints) p = 1.7f * (turn * p) + glm::vec3(5, 1, -2);
  const BoneRotations r = bone_rotations(joints);
  for (int b = 0; b < kBodyBones; ++b) {
    const bool vertical = kBoneRestDirection[b].y != 0.0f;
    const glm::quat expected = vertical ? glm::quat(1, 0, 0, 0) : turn;
    EXPECT_NEAR(quaternion_distance(r[b], expected), 0.0f, 1e-5f) << kJointNames[b];
  }
}

TEST(BoneRotations, FloatArrayMatchesVectors) {
  std::array<glm::vec3, kBodyJoints> joints = t_pose();
  joints[index(Joint::right_knee)] += glm::vec3(0.1f, 0.3f, 0.4f);
  joints[index(Joint::head)] += glm::vec3(0.0f, 0.0f, 0.2f);
  std::array<float, kBodyJoints * 3> flat;
  for (int j = 0; j < kBodyJoints; ++j) {
    for (int c = 0; c < 3; ++c) flat[3 * j + c] = joints[j][c];
  }
  const BoneRotations from_vectors = bone_rotations(joints);
  const BoneRotations from_floats = bone_rotations(flat);
  for (int b = 0; b < kBodyBones; ++b) EXPECT_EQ(from_vectors[b], from_floats[b]) << b;
  // A bone of zero length (or a missing joint) gives the identity.
  flat[3 * index(Joint::head)] = NAN;
  EXPECT_EQ(bone_rotations(flat)[index(Joint::head)], glm::quat(1, 0, 0, 0));
}

TEST(BoneRotations, LeeWeightsCountLimbsAndSpine) {
  float total = 0.0f;
  for (float w : kLeeBoneWeights) total += w;
  EXPECT_EQ(total, 11.0f);
  EXPECT_EQ(kLeeBoneWeights[index(Joint::head)], 0.0f);
  EXPECT_EQ(kLeeBoneWeights[index(Joint::neck)], 1.0f);
  EXPECT_EQ(kLeeBoneWeights[index(Joint::left_shoulder)], 0.0f);
  EXPECT_EQ(kLeeBoneWeights[index(Joint::left_elbow)], 1.0f);
}

}  // namespace
}  // namespace mocap::recon
