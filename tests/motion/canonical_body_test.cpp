#include "motion/canonical_body.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "motion/body_mapping.hpp"
#include "motion/bvh.hpp"
#include "motion/pose_sequence.hpp"
#include "support/shared_data.hpp"

namespace mocap::motion {
namespace {

constexpr int kRoot = index(Joint::root);
constexpr int kNeck = index(Joint::neck);
constexpr int kRs = index(Joint::right_shoulder);
constexpr int kLs = index(Joint::left_shoulder);
constexpr int kRh = index(Joint::right_hip);
constexpr int kLh = index(Joint::left_hip);

// A standing body facing +Z (left on +X), a little asymmetric and bent, in metres.
Body15 test_body() {
  Body15 b;
  b[kRoot] = {0.1f, 0.9f, -0.2f};
  b[kNeck] = b[kRoot] + glm::vec3(0.02f, 0.40f, 0.05f);
  b[index(Joint::head)] = b[kNeck] + glm::vec3(0.0f, 0.18f, 0.04f);
  b[kRs] = b[kNeck] + glm::vec3(-0.10f, -0.03f, 0.01f);
  b[kLs] = b[kNeck] + glm::vec3(0.11f, -0.02f, -0.01f);
  b[index(Joint::right_elbow)] = b[kRs] + glm::vec3(-0.05f, -0.22f, 0.1f);
  b[index(Joint::right_wrist)] = b[index(Joint::right_elbow)] + glm::vec3(0.0f, -0.1f, 0.2f);
  b[index(Joint::left_elbow)] = b[kLs] + glm::vec3(0.02f, -0.25f, -0.03f);
  b[index(Joint::left_wrist)] = b[index(Joint::left_elbow)] + glm::vec3(0.0f, -0.22f, 0.02f);
  b[kRh] = b[kRoot] + glm::vec3(-0.065f, 0.0f, 0.01f);
  b[kLh] = b[kRoot] - glm::vec3(-0.065f, 0.0f, 0.01f);
  b[index(Joint::right_knee)] = b[kRh] + glm::vec3(0.0f, -0.38f, 0.08f);
  b[index(Joint::right_ankle)] = b[index(Joint::right_knee)] + glm::vec3(0.0f, -0.40f, -0.05f);
  b[index(Joint::left_knee)] = b[kLh] + glm::vec3(0.01f, -0.39f, 0.0f);
  b[index(Joint::left_ankle)] = b[index(Joint::left_knee)] + glm::vec3(0.0f, -0.41f, 0.0f);
  return b;
}

float angle(const glm::vec3& a, const glm::vec3& b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f));
}

TEST(CanonicalBody, RetargetGivesTheLengthsAndKeepsLimbDirections) {
  const Body15 b = test_body();
  const BodyProportions& p = canonical_proportions();
  const Body15 r = retarget(b, p);
  EXPECT_EQ(r[kRoot], b[kRoot]);
  for (int j = 0; j < kBodyJoints; ++j) {
    const int parent = kJointParent[j];
    if (parent < 0) continue;
    EXPECT_NEAR(glm::distance(r[j], r[parent]), p.bone_m[j], 1e-5f) << kJointNames[j];
    if (j == kRs || j == kLs || j == kRh || j == kLh) continue;  // re-placed, see below
    EXPECT_LT(angle(r[j] - r[parent], b[j] - b[parent]), 1e-3f) << kJointNames[j];
  }
  // Hips symmetric about the root along the source hip line.
  EXPECT_LT(glm::length(r[kRh] + r[kLh] - 2.0f * r[kRoot]), 1e-6f);
  EXPECT_LT(angle(r[kLh] - r[kRh], b[kLh] - b[kRh]), 1e-3f);
  // Shoulders at the canonical angle to the trunk, on the source's side of it.
  const glm::vec3 trunk = r[kNeck] - r[kRoot];
  for (int s : {kRs, kLs}) {
    EXPECT_NEAR(angle(trunk, r[s] - r[kNeck]), p.shoulder_angle_rad, 1e-3f);
    const glm::vec3 t = glm::normalize(trunk);
    const glm::vec3 src = b[s] - b[kNeck], dst = r[s] - r[kNeck];
    EXPECT_LT(angle(src - glm::dot(src, t) * t, dst - glm::dot(dst, t) * t), 1e-3f);
  }
  EXPECT_NEAR(glm::distance(r[kRs], r[kLs]), p.shoulder_width_m(), 0.01f);
}

TEST(CanonicalBody, RetargetOntoItsOwnProportionsKeepsASymmetricBody) {
  Body15 b = test_body();
  // Make the shoulders symmetric about the trunk plane so that one angle describes both.
  b[kLs] = b[kNeck] + glm::vec3(0.10f, -0.03f, 0.01f);
  b[kNeck] = b[kRoot] + glm::vec3(0.0f, 0.40f, 0.0f);
  b[kRs] = b[kNeck] + glm::vec3(-0.10f, -0.03f, 0.01f);
  b[kLs] = b[kNeck] + glm::vec3(0.10f, -0.03f, 0.01f);
  const Body15 r = retarget(b, proportions_of(b));
  for (int j = 0; j < kBodyJoints; ++j)
    EXPECT_LT(glm::distance(r[j], b[j]), 1e-5f) << kJointNames[j];
}

TEST(CanonicalBody, MeasuredMediansPoolSidesAndSkipBrokenFrames) {
  std::vector<Body15> frames;
  for (float scale : {0.9f, 1.0f, 1.2f}) {
    Body15 b = test_body();
    for (auto& p : b) p = b[kRoot] + (p - b[kRoot]) * scale;
    frames.push_back(b);
  }
  Body15 broken = test_body();
  broken[3].x = std::nanf("");
  frames.push_back(broken);
  const BodyProportions one = proportions_of(test_body());
  const BodyProportions m = measure_proportions(frames, false);
  for (int j = 0; j < kBodyJoints; ++j) EXPECT_NEAR(m.bone_m[j], one.bone_m[j], 1e-5f);
  const BodyProportions s = measure_proportions(frames, true);
  for (int j = 0; j < kBodyJoints; ++j) {
    EXPECT_EQ(s.bone_m[j], s.bone_m[kJointMirror[j]]);
    EXPECT_NEAR(s.bone_m[j], 0.5f * (m.bone_m[j] + m.bone_m[kJointMirror[j]]), 1e-6f);
  }
  EXPECT_EQ(measure_proportions(std::vector<Body15>{broken}).bone_m[kNeck], 0.0f);
}

TEST(CanonicalBody, DegenerateInputGivesNoNaN) {
  Body15 b;
  b.fill(glm::vec3(0.0f));
  const Body15 r = retarget(b, canonical_proportions());
  for (const auto& p : r) EXPECT_TRUE(std::isfinite(p.x + p.y + p.z));
}

// The 15 body joints of every capture frame of `files` at 24 fps, as the database builder
// takes them (reference and blank frames dropped).
std::vector<Body15> bodies_of(const std::vector<std::string>& files) {
  std::vector<Body15> out;
  for (const auto& file : files) {
    const Clip clip = read_bvh(file);
    const BodyMapping m = map_to_body(clip.skeleton, file);
    const int first = m.first_frame_is_reference ? 1 : 0;
    const PoseSequence all = to_poses(clip);
    int start = first;
    while (start < clip.frame_count && is_blank_frame(clip, start)) ++start;
    const PoseSequence p = resample(slice(all, start, clip.frame_count - start), 24.0);
    GlobalPose g;
    for (int f = 0; f < p.frame_count; ++f) {
      forward_kinematics(p, f, g);
      Body15 b;
      body_positions(m, g, b);
      out.push_back(b);
    }
  }
  return out;
}

TEST(CanonicalBody, ConstantsAgreeWithCmuTrain) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/splits.txt");
  std::ifstream list(test::shared_data() / "mocap/cmu31/splits.txt");
  std::vector<std::string> files;
  std::string which, file;
  while (list >> which >> file) {
    if (which == "train") files.push_back((test::shared_data() / "mocap/cmu31" / file).string());
  }
  ASSERT_EQ(files.size(), 39u);
  const BodyProportions m = measure_proportions(bodies_of(files));
  const BodyProportions& c = canonical_proportions();
  std::cout << "measured: " << describe(m) << "\ncanonical: " << describe(c) << "\n";
  for (int j = 0; j < kBodyJoints; ++j)
    EXPECT_NEAR(m.bone_m[j], c.bone_m[j], 0.001f) << kJointNames[j];
  EXPECT_NEAR(m.shoulder_angle_rad, c.shoulder_angle_rad, 0.002f);
  // The shared facts (SKELETONS.md, bandai/README.md): trunk 419, upper arm 289, shoulder to
  // shoulder 367 mm, hips 151 mm apart.
  EXPECT_NEAR(c.bone_m[kNeck], 0.419f, 0.002f);
  EXPECT_NEAR(c.bone_m[index(Joint::right_elbow)], 0.289f, 0.002f);
  EXPECT_NEAR(c.shoulder_width_m(), 0.367f, 0.005f);
  EXPECT_NEAR(c.hip_width_m(), 0.151f, 0.003f);
}

// Standing height over joint span per train subject, from each subject's first train file's
// reference T-pose (frame 0 of the cgspeed files; every file of a subject has one skeleton).
TEST(CanonicalBody, StatureOverJointSpanAgreesWithCmuTrain) {
  MOCAP_REQUIRE_SHARED("mocap/cmu31/splits.txt");
  std::ifstream list(test::shared_data() / "mocap/cmu31/splits.txt");
  std::vector<std::string> subjects, files;
  std::string which, file;
  while (list >> which >> file) {
    const std::string subject = file.substr(0, file.find('_'));
    if (which != "train" || std::count(subjects.begin(), subjects.end(), subject)) continue;
    subjects.push_back(subject);
    files.push_back((test::shared_data() / "mocap/cmu31" / file).string());
  }
  ASSERT_EQ(subjects.size(), 6u);
  std::vector<float> ratios;
  std::cout << "| subject | stature m | joint span m | ratio |\n|---|---:|---:|---:|\n";
  for (std::size_t i = 0; i < files.size(); ++i) {
    const Clip clip = read_bvh(files[i]);
    const BodyMapping m = map_to_body(clip.skeleton, files[i]);
    const float stature = reference_stature_m(clip, m);
    const PoseSequence first = slice(to_poses(clip), 0, 1);
    GlobalPose g;
    forward_kinematics(first, 0, g);
    Body15 b;
    body_positions(m, g, b);
    const float span = joint_span_m(proportions_of(b));
    ratios.push_back(stature / span);
    std::cout << "| " << subjects[i] << " | " << stature << " | " << span << " | " << ratios.back()
              << " |\n";
    // As ../shared/data/mocap/README.md lists the T-pose spans (1.31 to 1.53 m).
    EXPECT_GT(stature, 1.3f) << files[i];
    EXPECT_LT(stature, 1.55f) << files[i];
    EXPECT_GT(stature, span) << files[i];
  }
  std::sort(ratios.begin(), ratios.end());
  const float median = 0.5f * (ratios[2] + ratios[3]);
  std::cout << "median ratio " << median << "; canonical stature " << canonical_stature_m()
            << " m\n";
  EXPECT_NEAR(median, kStatureOverJointSpan, 0.001f);
}

TEST(CanonicalBody, BandaiOnTheCanonicalBody) {
  MOCAP_REQUIRE_SHARED("mocap/bandai/dataset-1/dataset-1_walk_normal_001.bvh");
  const auto frames = bodies_of(
      {(test::shared_data() / "mocap/bandai/dataset-1/dataset-1_walk_normal_001.bvh").string()});
  ASSERT_FALSE(frames.empty());
  const BodyProportions source = measure_proportions(frames);
  // Bandai's shoulders are about 205 mm apart, CMU's 367 (bandai/README.md).
  const float width = glm::distance(frames[0][kRs], frames[0][kLs]);
  EXPECT_NEAR(width, 0.205f, 0.015f);
  EXPECT_LT(source.bone_m[kRs], 0.13f);
  const BodyProportions& c = canonical_proportions();
  for (const Body15& b : frames) {
    const Body15 r = retarget(b, c);
    const BodyProportions got = proportions_of(r);
    for (int j = 0; j < kBodyJoints; ++j) ASSERT_NEAR(got.bone_m[j], c.bone_m[j], 1e-4f);
    ASSERT_NEAR(glm::distance(r[kRs], r[kLs]), c.shoulder_width_m(), 0.02f);
  }
}

// Bandai's joints below the root have position channels; their values replace the OFFSET
// (bandai/README.md), they are not added to it.
TEST(CanonicalBody, PositionChannelsBelowTheRootReplaceTheOffset) {
  const std::string text =
      "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition "
      "Zrotation Yrotation Xrotation\n JOINT Spine\n {\n  OFFSET 100 200 300\n  CHANNELS 6 "
      "Xposition Yposition Zposition Zrotation Yrotation Xrotation\n  End Site\n  {\n   OFFSET 0 "
      "10 0\n  }\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.0333333\n"
      "1 2 3 0 0 0 0 5 0 0 0 0\n";
  const Clip clip = parse_bvh(text, "inline.bvh");
  const PoseSequence p = to_poses(clip);
  GlobalPose g;
  forward_kinematics(p, 0, g);
  EXPECT_NEAR(g.position[0].y, 2.0f, 1e-5f);
  EXPECT_NEAR(glm::distance(g.position[1], glm::vec3(1, 7, 3)), 0.0f, 1e-4f);  // not 101 207 303
  // The same holds for the real files: Bandai's Spine sits where its channels put it.
  MOCAP_REQUIRE_SHARED("mocap/bandai/dataset-1/dataset-1_walk_normal_001.bvh");
  const Clip bandai = read_bvh(
      (test::shared_data() / "mocap/bandai/dataset-1/dataset-1_walk_normal_001.bvh").string());
  const int spine = bandai.skeleton.find("Spine");
  ASSERT_GE(spine, 0);
  const SkeletonJoint& joint = bandai.skeleton.joints[spine];
  ASSERT_EQ(joint.channels.size(), 6u);
  const PoseSequence bp = to_poses(bandai);
  glm::vec3 channels{};
  for (int c = 0; c < 3; ++c) {
    const float v = bandai.frame(0)[joint.first_channel + c];
    const Channel ch = joint.channels[c];
    (ch == Channel::Xposition   ? channels.x
     : ch == Channel::Yposition ? channels.y
                                : channels.z) = v;
  }
  EXPECT_EQ(bp.translation[bp.at(0, spine)], channels);
}

}  // namespace
}  // namespace mocap::motion
