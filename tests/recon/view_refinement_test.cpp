#include "recon/view_refinement.hpp"

#include <gtest/gtest.h>
#include <glm/trigonometric.hpp>

#include "posedb/projection.hpp"

namespace mocap::recon {
namespace {

// A T-pose-like body with the arms a little forward, so that yaw is visible in 2D.
std::array<glm::vec3, kBodyJoints> body() {
  std::array<glm::vec3, kBodyJoints> b;
  b[index(Joint::head)] = {0, 0.75f, 0.05f};
  b[index(Joint::neck)] = {0, 0.45f, 0};
  b[index(Joint::right_shoulder)] = {-0.18f, 0.42f, 0};
  b[index(Joint::right_elbow)] = {-0.35f, 0.30f, 0.2f};
  b[index(Joint::right_wrist)] = {-0.40f, 0.20f, 0.45f};
  b[index(Joint::left_shoulder)] = {0.18f, 0.42f, 0};
  b[index(Joint::left_elbow)] = {0.45f, 0.42f, 0.05f};
  b[index(Joint::left_wrist)] = {0.70f, 0.42f, 0.1f};
  b[index(Joint::right_hip)] = {-0.08f, 0, 0};
  b[index(Joint::right_knee)] = {-0.1f, -0.42f, 0.1f};
  b[index(Joint::right_ankle)] = {-0.1f, -0.85f, 0};
  b[index(Joint::left_hip)] = {0.08f, 0, 0};
  b[index(Joint::left_knee)] = {0.12f, -0.40f, -0.1f};
  b[index(Joint::left_ankle)] = {0.15f, -0.83f, -0.2f};
  b[index(Joint::root)] = {0, 0, 0};
  return b;
}

TEST(ViewRefinement, RecoversAnOffGridView) {
  const posedb::View truth{31.0f, 2.1f, 4.0f, glm::degrees(std::atan2(2.1f - 0.95f, 4.0f))};
  std::array<glm::vec2, kBodyJoints> image;
  posedb::project_body(body(), posedb::view_camera(truth, 0.95f), image);
  posedb::PoseVector query;
  ASSERT_TRUE(posedb::normalize_pose(image, posedb::Scaling::bbox_height, query));
  const posedb::View grid{36.0f, 2.5f, 4.0f,
                          glm::degrees(std::atan2(2.5f - 0.95f, 4.0f))};  // the nearest grid view
  const posedb::View refined =
      refine_view(body(), query, grid, 0.95f, posedb::Scaling::bbox_height);
  EXPECT_NEAR(refined.yaw_deg, truth.yaw_deg, 0.6f);
  EXPECT_NEAR(refined.pitch_deg, truth.pitch_deg, 1.0f);
  EXPECT_NEAR(refined.height_m, truth.height_m, 0.1f);
}

TEST(ViewRefinement, MissingJointsAreLeftOutAndAPerfectMatchStays) {
  const posedb::View view{48.0f, 1.5f, 4.0f, glm::degrees(std::atan2(1.5f - 0.95f, 4.0f))};
  std::array<glm::vec2, kBodyJoints> image;
  posedb::project_body(body(), posedb::view_camera(view, 0.95f), image);
  posedb::PoseVector query;
  ASSERT_TRUE(posedb::normalize_pose(image, posedb::Scaling::bbox_height, query));
  query[2 * index(Joint::left_wrist)] = query[2 * index(Joint::left_wrist) + 1] = NAN;
  const posedb::View refined =
      refine_view(body(), query, view, 0.95f, posedb::Scaling::bbox_height);
  EXPECT_NEAR(refined.yaw_deg, view.yaw_deg, 1e-3f);
  EXPECT_NEAR(refined.height_m, view.height_m, 1e-3f);
}

}  // namespace
}  // namespace mocap::recon
