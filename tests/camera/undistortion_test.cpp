// undistort_pixel against OpenCV's own lens model (projectPoints).

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <vector>

#include "camera/undistortion.hpp"

namespace mocap::camera {
namespace {

// A point pushed through OpenCV's lens model comes back where it was; no distortion: unchanged.
TEST(Undistortion, UndoesTheLensModelAndLeavesAnIdealCameraAlone) {
  CameraIntrinsics lens = from_fov(1280, 720, 70.0);
  lens.distortion = {-0.28, 0.09, 0.001, -0.0005, 0.0};
  const std::vector<cv::Point3f> rays{{0.31f, -0.22f, 1.0f}, {-0.4f, 0.25f, 1.0f}};
  std::vector<cv::Point2f> distorted, ideal;
  const cv::Matx33d K(lens.K.data());
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, lens.distortion, distorted);
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, cv::noArray(), ideal);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    ASSERT_GT(cv::norm(distorted[i] - ideal[i]), 5.0);  // the lens really moves the point
    const auto back = undistort_pixel(lens, distorted[i].x, distorted[i].y);
    EXPECT_NEAR(back[0], ideal[i].x, 0.05);
    EXPECT_NEAR(back[1], ideal[i].y, 0.05);
  }
  const auto same = undistort_pixel(from_fov(1280, 720, 70.0), 100.5f, 200.25f);
  EXPECT_EQ(same[0], 100.5f);
  EXPECT_EQ(same[1], 200.25f);
}

}  // namespace
}  // namespace mocap::camera
