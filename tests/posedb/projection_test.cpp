#include "posedb/projection.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <glm/trigonometric.hpp>

#include "posedb/normalization.hpp"
#include "posedb/view_set.hpp"

namespace mocap::posedb {
namespace {

std::array<glm::vec3, kBodyJoints> one_point_body(glm::vec3 p) {
  std::array<glm::vec3, kBodyJoints> b;
  b.fill(glm::vec3(0));
  b[0] = p;
  return b;
}

TEST(ViewSet, DefaultIsThirtyYawsAtFourHeights) {
  const auto views = make_views(ViewSetOptions{});
  ASSERT_EQ(views.size(), 120u);
  EXPECT_FLOAT_EQ(views[1].yaw_deg, 12.0f);
  EXPECT_FLOAT_EQ(views[30].height_m, 2.5f);
  // 1.5 m camera, 4 m away, root at 0.95 m: atan(0.55 / 4) = 7.83 degrees down.
  EXPECT_NEAR(views[0].pitch_deg, 7.829f, 1e-2);
  EXPECT_GT(views[119].pitch_deg, 45.0f);
}

// Hand-computed: a level camera 4 m in front (yaw 0) at root height.
TEST(Projection, LevelFrontCamera) {
  const View v{0.0f, 0.95f, 4.0f, 0.0f};
  const camera::Camera cam = view_camera(v, 0.95f);
  EXPECT_NEAR(cam.centre().z, 4.0, 1e-6);
  EXPECT_NEAR(cam.optical_axis().z, -1.0, 1e-6);  // looking at the root
  std::array<glm::vec2, kBodyJoints> out;
  // A point 1 m up and 0.5 m to the person's left (+X): image right, up (y negative), at depth 4.
  project_body(one_point_body({0.5f, 1.0f, 0.0f}), cam, out);
  EXPECT_NEAR(out[0].x, 0.5f / 4.0f, 1e-6);
  EXPECT_NEAR(out[0].y, -1.0f / 4.0f, 1e-6);
  // A point 1 m towards the camera is nearer: x / 3.
  project_body(one_point_body({0.3f, 0.0f, 1.0f}), cam, out);
  EXPECT_NEAR(out[0].x, 0.1f, 1e-6);
  EXPECT_NEAR(out[1].x, 0.0f, 1e-6);  // the root projects to the image centre
}

TEST(Projection, SideCameraSeesDepthAsX) {
  // Yaw 90: the camera stands at the person's left (+X) looking towards -X. The person's front
  // (+Z) then appears on the image left.
  const camera::Camera cam = view_camera({90.0f, 0.95f, 4.0f, 0.0f}, 0.95f);
  std::array<glm::vec2, kBodyJoints> out;
  project_body(one_point_body({0.0f, 0.0f, 1.0f}), cam, out);
  EXPECT_NEAR(out[0].x, -0.25f, 1e-6);
  EXPECT_NEAR(out[0].y, 0.0f, 1e-6);
}

TEST(Projection, PitchedCameraLooksAtTheRoot) {
  const camera::Camera cam = view_camera({0.0f, 4.95f, 4.0f, 45.0f}, 0.95f);
  std::array<glm::vec2, kBodyJoints> out;
  project_body(one_point_body({0.0f, 0.0f, 0.0f}), cam, out);
  EXPECT_NEAR(out[0].x, 0.0f, 1e-6);
  EXPECT_NEAR(out[0].y, 0.0f, 1e-6);
  // A point above the root appears above the image centre, foreshortened by the 45 degree tilt.
  project_body(one_point_body({0.0f, 1.0f, 0.0f}), cam, out);
  EXPECT_LT(out[0].y, 0.0f);
  EXPECT_NEAR(out[0].y,
              -std::cos(glm::radians(45.0f)) / (std::sqrt(32.0f) - std::sin(glm::radians(45.0f))),
              1e-5);
}

std::array<glm::vec2, kBodyJoints> random_pose(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-100.0f, 100.0f);
  std::array<glm::vec2, kBodyJoints> p;
  for (auto& x : p) x = {u(rng), u(rng)};
  return p;
}

TEST(Normalization, InvariantToImageScaleAndTranslation) {
  std::mt19937 rng(3);
  for (Scaling s : {Scaling::bbox_height, Scaling::bone_length}) {
    for (int trial = 0; trial < 100; ++trial) {
      auto a = random_pose(rng);
      auto b = a;
      const float scale = 0.1f + static_cast<float>(rng() % 100) / 10.0f;
      const glm::vec2 shift(static_cast<float>(rng() % 2000), -static_cast<float>(rng() % 500));
      for (auto& p : b) p = p * scale + shift;
      PoseVector na, nb;
      ASSERT_TRUE(normalize_pose(a, s, na));
      ASSERT_TRUE(normalize_pose(b, s, nb));
      for (int d = 0; d < kPoseDims; ++d) ASSERT_NEAR(na[d], nb[d], 1e-4f);
    }
  }
}

TEST(Normalization, BoxHeightIsOneAndRootIsOrigin) {
  std::mt19937 rng(5);
  auto a = random_pose(rng);
  PoseVector n;
  ASSERT_TRUE(normalize_pose(a, Scaling::bbox_height, n));
  float lo = 0, hi = 0;  // the root (0, 0) is part of the box
  for (int j = 0; j < kBodyJoints - 1; ++j)
    lo = std::min(lo, n[2 * j + 1]), hi = std::max(hi, n[2 * j + 1]);
  EXPECT_NEAR(hi - lo, 1.0f, 1e-5);
}

TEST(Normalization, MissingJointsStayMissingAndMissingRootFails) {
  std::mt19937 rng(9);
  auto a = random_pose(rng);
  a[index(Joint::left_wrist)] = {NAN, NAN};
  PoseVector n;
  ASSERT_TRUE(normalize_pose(a, Scaling::bbox_height, n));
  EXPECT_TRUE(std::isnan(n[2 * index(Joint::left_wrist)]));
  a[index(Joint::root)] = {NAN, NAN};
  EXPECT_FALSE(normalize_pose(a, Scaling::bbox_height, n));
  auto flat = random_pose(rng);
  for (auto& p : flat) p.y = 3.0f;  // zero height
  EXPECT_FALSE(normalize_pose(flat, Scaling::bbox_height, n));
}

}  // namespace
}  // namespace mocap::posedb
