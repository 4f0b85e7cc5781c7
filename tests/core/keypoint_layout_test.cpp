#include "core/keypoint_layout.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace mocap {
namespace {

TEST(Body15, NamesRoundTrip) {
  for (int j = 0; j < kBodyJoints; ++j) {
    const auto joint = joint_from_name(kJointNames[j]);
    ASSERT_TRUE(joint.has_value());
    EXPECT_EQ(index(*joint), j);
  }
  EXPECT_FALSE(joint_from_name("pelvis").has_value());
}

TEST(Body15, ParentsFormATreeRootedAtRoot) {
  for (int j = 0; j < kBodyJoints; ++j) {
    int steps = 0;
    for (int k = j; k != index(Joint::root); k = kJointParent[k]) {
      ASSERT_GE(kJointParent[k], 0) << kJointNames[j];
      ASSERT_LT(++steps, kBodyJoints) << "cycle at " << kJointNames[j];
    }
    EXPECT_EQ(kJointMirror[kJointMirror[j]], j);
  }
}

TEST(KeypointLayout, FindsLayoutsByLooseNames) {
  EXPECT_EQ(find_layout("coco17")->id, LayoutId::coco17);
  EXPECT_EQ(find_layout("BODY_25B")->id, LayoutId::body25b);
  EXPECT_EQ(find_layout("body-25")->id, LayoutId::body25);
  EXPECT_EQ(find_layout("HumanEva-15")->keypoints.size(), 15u);
  EXPECT_EQ(find_layout("openpose"), nullptr);
  for (const auto& l : all_layouts()) {
    for (const auto& s : l.body) {
      EXPECT_LT(s.first, static_cast<int>(l.keypoints.size())) << l.name;
      EXPECT_LT(s.second, static_cast<int>(l.keypoints.size())) << l.name;
    }
  }
}

// COCO-17 keypoint k placed at (k, 10k) with confidence 1.
std::vector<float> coco_points() {
  std::vector<float> xyc;
  for (int k = 0; k < 17; ++k) xyc.insert(xyc.end(), {float(k), 10.0f * k, 1.0f});
  return xyc;
}

TEST(KeypointLayout, Coco17DerivesNeckHeadAndRoot) {
  std::vector<float> body(kBodyJoints * 3);
  to_body15(layout(LayoutId::coco17), coco_points(), body);
  // neck = midpoint of shoulders 5 and 6; root = midpoint of hips 11 and 12; head = ears 3 and 4.
  EXPECT_FLOAT_EQ(body[3 * index(Joint::neck)], 5.5f);
  EXPECT_FLOAT_EQ(body[3 * index(Joint::root) + 1], 115.0f);
  EXPECT_FLOAT_EQ(body[3 * index(Joint::head)], 3.5f);
  // right wrist = COCO 10, left ankle = COCO 15.
  EXPECT_FLOAT_EQ(body[3 * index(Joint::right_wrist)], 10.0f);
  EXPECT_FLOAT_EQ(body[3 * index(Joint::left_ankle)], 15.0f);
}

TEST(KeypointLayout, MissingKeypointsGiveMissingJoints) {
  auto xyc = coco_points();
  xyc[3 * 3 + 2] = 0.0f;   // left ear missing: head from the right ear
  xyc[3 * 11 + 2] = 0.0f;  // left hip missing: no root
  xyc[3 * 9] = std::numeric_limits<float>::quiet_NaN();  // left wrist NaN
  std::vector<float> body(kBodyJoints * 3);
  to_body15(layout(LayoutId::coco17), xyc, body);
  EXPECT_FLOAT_EQ(body[3 * index(Joint::head)], 4.0f);
  EXPECT_TRUE(std::isnan(body[3 * index(Joint::root)]));
  EXPECT_EQ(body[3 * index(Joint::root) + 2], 0.0f);
  EXPECT_TRUE(std::isnan(body[3 * index(Joint::left_wrist)]));
}

TEST(KeypointLayout, ShortInputIsRejected) {
  std::vector<float> body(kBodyJoints * 3), xyc(10);
  EXPECT_THROW(to_body15(layout(LayoutId::body25), xyc, body), std::invalid_argument);
}

}  // namespace
}  // namespace mocap
