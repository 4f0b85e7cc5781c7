// Duplicate removal and the detector-box-to-followed-person assignment: two people embracing
// (boxes overlapping by more than the box rule's 0.6, skeletons apart) stay two under the
// keypoint-similarity rule and are made one by the box rule; two finds of one person (keypoints a
// few pixels apart, boxes differing) are one under both; a merged box followed over two people
// claims one of their two detector boxes when each followed person is at most one box.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "detect/centernet.hpp"
#include "detect/person_boxes.hpp"
#include "detect/topdown_detector.hpp"

namespace mocap::detect {
namespace {

// A standing person's COCO-17 keypoints, 400 px from eyes to ankles, x of the body's middle at
// `cx`, eyes at y 100 (proportions of an adult: shoulders 0.18 below the eyes, hips 0.47, knees
// 0.73, ankles 1.0 of that height; shoulders 0.2 of it across, hips 0.14).
MovenetPerson standing(float cx, float dx_face = 0) {
  constexpr float kTop = 100, kTall = 400;
  // {x offset from the middle, y share of the height} per keypoint, COCO order.
  constexpr std::array<std::array<float, 2>, kMovenetKeypoints> kShape = {{
      {0.00f, 0.02f},
      {-0.02f, 0.0f},
      {0.02f, 0.0f},
      {-0.05f, 0.01f},
      {0.05f, 0.01f},
      {-0.10f, 0.18f},
      {0.10f, 0.18f},
      {-0.13f, 0.33f},
      {0.13f, 0.33f},
      {-0.14f, 0.46f},
      {0.14f, 0.46f},
      {-0.07f, 0.47f},
      {0.07f, 0.47f},
      {-0.07f, 0.73f},
      {0.07f, 0.73f},
      {-0.07f, 1.00f},
      {0.07f, 1.00f},
  }};
  MovenetPerson p;
  for (int k = 0; k < kMovenetKeypoints; ++k) {
    const auto& [x, y] = kShape[static_cast<std::size_t>(k)];
    p.keypoints[k] = {cx + x * kTall + (k < 5 ? dx_face : 0), kTop + y * kTall, 0.9f};
  }
  p.box = keypoint_box(p.keypoints, 0.12f);
  p.score = 0.9f;
  return p;
}

TEST(KeypointSimilarity, IsOneOnTheSamePointsAndFallsWithDistance) {
  const MovenetPerson a = standing(300);
  int common = 0;
  EXPECT_FLOAT_EQ(keypoint_similarity(a, a, common), 1.0f);
  EXPECT_EQ(common, kMovenetKeypoints);
  const float near = keypoint_similarity(a, standing(303), common);
  const float far = keypoint_similarity(a, standing(380), common);
  EXPECT_GT(near, 0.9f);  // 3 px on a 450-px person
  EXPECT_LT(far, near);
  EXPECT_LT(far, 0.2f);  // a neighbour 80 px aside
  MovenetPerson none = a;
  for (Keypoint2D& k : none.keypoints) k = {std::nanf(""), std::nanf(""), 0};
  EXPECT_EQ(keypoint_similarity(a, none, common), 0.0f);
  EXPECT_EQ(common, 0);
}

// Two people embracing: skeletons 30 px apart (a third of the shoulders' width), boxes
// overlapping by more than 0.6.
TEST(DuplicateTest, TwoPeopleEmbracingStayTwoByKeypointSimilarity) {
  const std::vector<MovenetPerson> couple = {standing(300), standing(330)};
  ASSERT_GT(iou(couple[0].box, couple[1].box), 0.6f);
  std::vector<DuplicateRule> why;
  EXPECT_EQ(distinct_people(couple, DuplicateTest{0.6f, 0.05f, 0.0f}, &why).size(), 1u);
  EXPECT_EQ(why[1], DuplicateRule::box_overlap);
  EXPECT_EQ(distinct_people(couple, DuplicateTest{0.6f, 0.05f, 0.9f}, &why).size(), 2u);
  EXPECT_EQ(why[1], DuplicateRule::none);
}

// One person found twice (another crop: keypoints 3 px aside, the face turned): one either way.
TEST(DuplicateTest, TwoFindsOfOnePersonAreOneByEitherRule) {
  MovenetPerson second = standing(303, 4);
  second.score = 0.5f;
  const std::vector<MovenetPerson> twice = {standing(300), second};
  std::vector<DuplicateRule> why;
  EXPECT_EQ(distinct_people(twice, DuplicateTest{0.6f, 0.05f, 0.9f}, &why),
            std::vector<std::size_t>{0});
  EXPECT_EQ(why[1], DuplicateRule::keypoint_similarity);
  EXPECT_EQ(distinct_people(twice, DuplicateTest{0.6f, 0.05f, 0.0f}, &why).size(), 1u);
  EXPECT_EQ(why[1], DuplicateRule::box_overlap);
}

// Finds sharing fewer than 3 keypoints (a detector's sure box with none) fall back on boxes.
TEST(DuplicateTest, FindsWithFewKeypointsInCommonAreComparedByBox) {
  MovenetPerson bare = standing(300);
  for (Keypoint2D& k : bare.keypoints) k = {std::nanf(""), std::nanf(""), 0};
  bare.score = 0.1f;
  const std::vector<MovenetPerson> both = {standing(300), bare};
  std::vector<DuplicateRule> why;
  EXPECT_EQ(distinct_people(both, DuplicateTest{0.6f, 0.05f, 0.9f}, &why).size(), 1u);
  EXPECT_EQ(why[1], DuplicateRule::box_overlap);
}

// A box followed over two people (the couple as one) and the detector's two boxes, one per
// person, each overlapping it by more than 0.3.
TEST(FollowedBoxes, AFollowedPersonIsAtMostOneBoxWhenAskedSo) {
  const std::vector<Box2D> followed = {{200, 100, 200, 400}, {700, 100, 100, 400}};
  const std::vector<Detection> detections = {{{200, 100, 110, 400}, 0.6f},
                                             {{290, 100, 110, 400}, 0.5f},
                                             {{705, 100, 100, 400}, 0.7f},
                                             {{1000, 100, 100, 400}, 0.4f}};
  for (std::size_t d = 0; d < 2; ++d) ASSERT_GT(iou(followed[0], detections[d].box), 0.3f);
  EXPECT_EQ(followed_boxes(followed, detections, 0.3f, false), (std::vector<int>{0, 0, 1, -1}));
  // Equal overlaps: the first detection (best scored) is the followed person's.
  EXPECT_EQ(followed_boxes(followed, detections, 0.3f, true), (std::vector<int>{0, -1, 1, -1}));
}

}  // namespace
}  // namespace mocap::detect
