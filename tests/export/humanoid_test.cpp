// The 15-joint body as a Unity humanoid: a T-pose gives identity rotations, forward kinematics
// through the humanoid (Unity axes) gives back every joint of real CMU motion, and bad input
// gives finite unit quaternions.

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "export/humanoid.hpp"
#include "motion/body_mapping.hpp"
#include "motion/bvh.hpp"
#include "motion/pose_sequence.hpp"
#include "support/shared_data.hpp"

namespace mocap::exporting {
namespace {

using B = HumanBone;
constexpr int id(B b) { return static_cast<int>(b); }

std::array<glm::vec3, kBodyJoints> t_pose() {
  std::array<glm::vec3, kBodyJoints> w;
  auto set = [&](Joint j, float x, float y, float z) { w[index(j)] = glm::vec3(x, y, z); };
  set(Joint::root, 0.5f, 0.95f, -2.0f);
  set(Joint::neck, 0.5f, 1.40f, -2.0f);
  set(Joint::head, 0.5f, 1.60f, -2.0f);
  for (float s : {1.0f, -1.0f}) {  // person's left is +X in our world
    const bool left = s > 0;
    set(left ? Joint::left_shoulder : Joint::right_shoulder, 0.5f + s * 0.18f, 1.40f, -2.0f);
    set(left ? Joint::left_elbow : Joint::right_elbow, 0.5f + s * 0.47f, 1.40f, -2.0f);
    set(left ? Joint::left_wrist : Joint::right_wrist, 0.5f + s * 0.67f, 1.40f, -2.0f);
    set(left ? Joint::left_hip : Joint::right_hip, 0.5f + s * 0.08f, 0.95f, -2.0f);
    set(left ? Joint::left_knee : Joint::right_knee, 0.5f + s * 0.08f, 0.53f, -2.0f);
    set(left ? Joint::left_ankle : Joint::right_ankle, 0.5f + s * 0.08f, 0.10f, -2.0f);
  }
  return w;
}

float angle(const glm::quat& q) { return 2.0f * std::acos(std::min(1.0f, std::abs(q.w))); }

TEST(Humanoid, TPoseIsTheRestPose) {
  const HumanoidPose pose = humanoid_pose(t_pose());
  for (int b = 0; b < kHumanBones; ++b)
    EXPECT_LT(angle(pose.rotation[b]), 1e-3f) << kHumanBoneNames[b];
  // Unity: left-handed, so the avatar's left arm points to -X; the root under the hips.
  EXPECT_NEAR(pose.root_position.x, -0.5f, 1e-6f);
  EXPECT_NEAR(pose.root_position.y, 0.0f, 1e-6f);
  EXPECT_NEAR(pose.root_position.z, -2.0f, 1e-6f);
  EXPECT_NEAR(pose.position[id(B::Hips)].y, 0.95f, 1e-6f);
  EXPECT_LT(pose.position[id(B::LeftLowerArm)].x, -0.2f);
  EXPECT_GT(pose.position[id(B::RightLowerArm)].x, 0.2f);
  EXPECT_NEAR(pose.position[id(B::LeftLowerLeg)].y, -0.42f, 1e-5f);
}

TEST(Humanoid, TurningTheBodyTurnsTheHipsOnly) {
  // The whole T-pose turned 90 degrees to its left (about +Y) around the root.
  std::array<glm::vec3, kBodyJoints> w = t_pose();
  const glm::vec3 root = w[index(Joint::root)];
  const glm::quat turn = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0));
  for (glm::vec3& p : w) p = root + turn * (p - root);
  const HumanoidPose pose = humanoid_pose(w);
  EXPECT_NEAR(angle(pose.rotation[id(B::Hips)]), glm::radians(90.0f), 1e-4f);
  // Unity's mirror turns the axis: a left turn about +Y is (0, -sin 45, 0, cos 45) there.
  EXPECT_NEAR(pose.rotation[id(B::Hips)].y * pose.rotation[id(B::Hips)].w, -0.5f, 1e-4f);
  for (int b = 1; b < kHumanBones; ++b)
    EXPECT_LT(angle(pose.rotation[b]), 1e-3f) << kHumanBoneNames[b];
}

// Forward kinematics in Unity's axes: every bone's global position.
std::array<glm::vec3, kHumanBones> forward(const HumanoidPose& pose) {
  std::array<glm::vec3, kHumanBones> position;
  std::array<glm::quat, kHumanBones> rotation;
  for (int b = 0; b < kHumanBones; ++b) {
    const int parent = kHumanBoneParent[b];
    const glm::vec3 p0 = parent < 0 ? pose.root_position : position[parent];
    const glm::quat r0 = parent < 0 ? pose.root_rotation : rotation[parent];
    position[b] = p0 + r0 * pose.position[b];
    rotation[b] = r0 * pose.rotation[b];
  }
  return position;
}

TEST(Humanoid, ForwardKinematicsGivesBackTheJointsOfCmuMotion) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/09_03.bvh");
  const motion::Clip clip =
      motion::read_bvh((test::shared_data() / "mocap/cmu31/09_03.bvh").string());
  const motion::BodyMapping mapping = motion::map_to_body(clip.skeleton, clip.source);
  const motion::PoseSequence poses = motion::to_poses(clip);
  const std::pair<B, Joint> checks[] = {{B::Hips, Joint::root},
                                        {B::Neck, Joint::neck},
                                        {B::LeftUpperArm, Joint::left_shoulder},
                                        {B::LeftLowerArm, Joint::left_elbow},
                                        {B::LeftHand, Joint::left_wrist},
                                        {B::RightUpperArm, Joint::right_shoulder},
                                        {B::RightLowerArm, Joint::right_elbow},
                                        {B::RightHand, Joint::right_wrist},
                                        {B::LeftUpperLeg, Joint::left_hip},
                                        {B::LeftLowerLeg, Joint::left_knee},
                                        {B::LeftFoot, Joint::left_ankle},
                                        {B::RightUpperLeg, Joint::right_hip},
                                        {B::RightLowerLeg, Joint::right_knee},
                                        {B::RightFoot, Joint::right_ankle}};
  float worst = 0.0f;
  motion::GlobalPose global;
  for (int f = 1; f < clip.frame_count; f += 16) {
    motion::forward_kinematics(poses, f, global);
    std::array<glm::vec3, kBodyJoints> w;
    motion::body_positions(mapping, global, w);
    const HumanoidPose pose = humanoid_pose(w);
    for (const glm::quat& q : pose.rotation) EXPECT_NEAR(glm::length(q), 1.0f, 1e-5f);
    const std::array<glm::vec3, kHumanBones> fk = forward(pose);
    for (const auto& [bone, joint] : checks) {
      const float error = glm::length(fk[id(bone)] - to_unity(w[index(joint)]));
      worst = std::max(worst, error);
      EXPECT_LT(error, 1e-4f) << kHumanBoneNames[id(bone)] << " frame " << f;
    }
    // The head bone on the way from the neck to the top of the head.
    const glm::vec3 head =
        w[index(Joint::neck)] + 0.35f * (w[index(Joint::head)] - w[index(Joint::neck)]);
    EXPECT_LT(glm::length(fk[id(B::Head)] - to_unity(head)), 1e-4f) << "frame " << f;
  }
  std::cout << "[ note ] worst joint error through the humanoid: " << worst * 1000.0f << " mm\n";
}

TEST(Humanoid, BadJointsGiveFiniteUnitQuaternions) {
  std::array<glm::vec3, kBodyJoints> w = t_pose();
  w[index(Joint::left_elbow)] = glm::vec3(std::numeric_limits<float>::quiet_NaN());
  w[index(Joint::right_knee)] = w[index(Joint::right_hip)];  // zero-length thigh
  w[index(Joint::neck)] = w[index(Joint::root)];             // no trunk
  for (const auto& points : {w, std::array<glm::vec3, kBodyJoints>{}}) {
    const HumanoidPose pose = humanoid_pose(points);
    for (int b = 0; b < kHumanBones; ++b) {
      const glm::quat& q = pose.rotation[b];
      EXPECT_TRUE(std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) &&
                  std::isfinite(q.z))
          << kHumanBoneNames[b];
      EXPECT_NEAR(glm::length(q), 1.0f, 1e-5f) << kHumanBoneNames[b];
    }
  }
}

}  // namespace
}  // namespace mocap::exporting
