#include "motion/pose_sequence.hpp"

#include <gtest/gtest.h>

#include "cmu_asf_fixture.hpp"
#include "motion/asf_amc.hpp"
#include "motion/body_mapping.hpp"
#include "motion/bvh.hpp"
#include "support/shared_data.hpp"

namespace mocap::motion {
namespace {

PoseSequence load(const std::string& relative) {
  return to_poses(read_bvh((test::shared_data() / relative).string()));
}

bool has_position_channel(const SkeletonJoint& j) {
  return std::any_of(j.channels.begin(), j.channels.end(),
                     [](Channel c) { return !is_rotation(c); });
}

// Bone lengths (parent to child distance) stay constant over a clip after FK, for each family.
// A joint with position channels (a root, Bandai's Hips) is moved by them, not held by a bone.
void expect_constant_bones(const PoseSequence& p, float tolerance) {
  GlobalPose g;
  forward_kinematics(p, 0, g);
  std::vector<float> first(p.joint_count());
  for (int j = 1; j < p.joint_count(); ++j)
    first[j] = glm::distance(g.position[j], g.position[p.skeleton.joints[j].parent]);
  for (int f = 1; f < p.frame_count; f += 7) {
    forward_kinematics(p, f, g);
    for (int j = 1; j < p.joint_count(); ++j) {
      if (p.skeleton.joints[j].parent == 0 && has_position_channel(p.skeleton.joints[j])) continue;
      const float d = glm::distance(g.position[j], g.position[p.skeleton.joints[j].parent]);
      ASSERT_NEAR(d, first[j], tolerance) << p.skeleton.joints[j].name << " frame " << f;
    }
  }
}

TEST(ForwardKinematics, BoneLengthsConstantCmu) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/07_01.bvh");
  expect_constant_bones(load("mocap/cmu31/07_01.bvh"), 1e-3f);
}

TEST(ForwardKinematics, BoneLengthsConstantDazAndBandai) {
  MOCAP_REQUIRE_SHARED("mocap/bandai/dataset-1/dataset-1_walk_normal_001.bvh");
  expect_constant_bones(load("mocap/cmu_daz/07_01.bvh"), 1e-2f);
  expect_constant_bones(load("mocap/bandai/dataset-1/dataset-1_walk_normal_001.bvh"), 1e-2f);
}

TEST(Resample, IntegerRatioKeepsEveryFifthFrame) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/07_01.bvh");
  const PoseSequence p = load("mocap/cmu31/07_01.bvh");
  const PoseSequence r = resample(p, 24.0);
  EXPECT_EQ(r.frame_count, (p.frame_count - 1) / 5 + 1);
  for (int k = 0; k < r.frame_count; k += 11) {
    for (int j = 0; j < p.joint_count(); ++j) {
      EXPECT_EQ(r.rotation[r.at(k, j)], p.rotation[p.at(5 * k, j)]);
      EXPECT_EQ(r.translation[r.at(k, j)], p.translation[p.at(5 * k, j)]);
    }
  }
}

TEST(Resample, SlerpHalfwayAndFrameCount) {
  PoseSequence p;
  p.skeleton.joints.push_back({"root", -1, {}, {}, false, 0});
  p.fps = 30.0;
  p.frame_count = 2;
  p.translation = {{0, 0, 0}, {2, 0, 0}};
  p.rotation = {glm::quat(1, 0, 0, 0), glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0))};
  const PoseSequence r = resample(p, 60.0);
  ASSERT_EQ(r.frame_count, 3);
  EXPECT_NEAR(r.translation[1].x, 1.0f, 1e-6);
  EXPECT_NEAR(glm::degrees(glm::angle(r.rotation[1])), 45.0f, 1e-3);
  // 30 -> 24 fps: floor((n - 1) * 24 / 30) + 1 frames (Bandai README).
  PoseSequence q = p;
  q.frame_count = 31;
  q.translation.assign(31, glm::vec3(0));
  q.rotation.assign(31, glm::quat(1, 0, 0, 0));
  EXPECT_EQ(resample(q, 24.0).frame_count, 25);
}

TEST(Resample, ShorterArcIsTaken) {
  PoseSequence p;
  p.skeleton.joints.push_back({"root", -1, {}, {}, false, 0});
  p.fps = 2.0;
  p.frame_count = 2;
  p.translation = {{0, 0, 0}, {0, 0, 0}};
  const glm::quat q = glm::angleAxis(glm::radians(10.0f), glm::vec3(0, 0, 1));
  p.rotation = {q, -q};  // the same rotation with the sign flipped
  const PoseSequence r = resample(p, 4.0);
  EXPECT_NEAR(glm::degrees(glm::angle(r.rotation[1])), 10.0f, 1e-2);
}

// Body15 mapping per family: plausible sizes in metres.
void expect_plausible_body(const std::string& relative, Family family, int frame) {
  const Clip clip = read_bvh((test::shared_data() / relative).string());
  const BodyMapping m = map_to_body(clip.skeleton, relative);
  EXPECT_EQ(m.family, family) << relative;
  const PoseSequence p = to_poses(clip);
  GlobalPose g;
  forward_kinematics(p, frame, g);
  std::array<glm::vec3, kBodyJoints> b;
  body_positions(m, g, b);
  const float thigh = glm::distance(b[index(Joint::left_hip)], b[index(Joint::left_knee)]);
  const float shoulders =
      glm::distance(b[index(Joint::left_shoulder)], b[index(Joint::right_shoulder)]);
  const float head_above_root = b[index(Joint::head)].y - b[index(Joint::root)].y;
  EXPECT_GT(thigh, 0.3f) << relative;
  EXPECT_LT(thigh, 0.5f) << relative;
  EXPECT_GT(shoulders, 0.15f) << relative;
  EXPECT_LT(shoulders, 0.45f) << relative;
  EXPECT_GT(head_above_root, 0.5f) << relative;  // standing in these frames
  EXPECT_LT(head_above_root, 0.9f) << relative;
  // Left is on +X when facing +Z in every family's reference pose.
}

TEST(BodyMapping, EveryFamilyGivesAPlausibleBody) {
  MOCAP_REQUIRE_SHARED("mocap/bandai/dataset-1/dataset-1_walk_normal_001.bvh");
  expect_plausible_body("mocap/cmu31/07_01.bvh", Family::cmu31, 10);
  expect_plausible_body("mocap/cmu31/86_01.bvh", Family::cmu31, 10);
  expect_plausible_body("mocap/cmu_daz/07_01.bvh", Family::cmu_daz, 10);
  expect_plausible_body("mocap/bandai/dataset-1/dataset-1_walk_normal_001.bvh", Family::bandai, 10);
}

TEST(BodyMapping, CmuAsfAmcIsRecognisedAndScaledToMetres) {
  const AsfSkeleton asf = parse_asf(test::cmu_like_asf(), "cmu_like.asf");
  const Clip clip = parse_amc(asf, test::cmu_like_amc(3), "cmu_like.amc", kCmuFps);
  const BodyMapping m = map_to_body(clip.skeleton, "cmu_like.asf");
  EXPECT_EQ(m.family, Family::cmu_asf);
  const PoseSequence p = to_poses(clip);
  GlobalPose g;
  forward_kinematics(p, 0, g);
  std::array<glm::vec3, kBodyJoints> b;
  body_positions(m, g, b);
  // Femur length 7.2 ASF units = 0.406 m; the head top is above the neck, the left hand on +X.
  EXPECT_NEAR(glm::distance(b[index(Joint::left_hip)], b[index(Joint::left_knee)]),
              7.2f * 0.056444f, 1e-3);
  EXPECT_GT(b[index(Joint::head)].y, b[index(Joint::neck)].y);
  EXPECT_GT(b[index(Joint::left_wrist)].x, b[index(Joint::right_wrist)].x);
}

TEST(BodyMapping, UnknownSkeletonNamesWhatIsMissing) {
  Skeleton s;
  s.joints.push_back({"Pelvis", -1, {}, {}, false, 0});
  try {
    map_to_body(s, "odd.bvh");
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("odd.bvh"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("left_elbow"), std::string::npos);
  }
}

}  // namespace
}  // namespace mocap::motion
