#include "camera/undistortion.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/calib3d.hpp>

namespace mocap::camera {

std::array<float, 2> undistort_pixel(const CameraIntrinsics& camera, float x, float y) {
  const bool distorted = std::any_of(camera.distortion.begin(), camera.distortion.end(),
                                     [](double d) { return d != 0.0; });
  if (!distorted || !std::isfinite(x) || !std::isfinite(y)) return {x, y};
  const cv::Matx33d K(camera.K.data());
  const std::vector<cv::Point2f> in{{x, y}};
  std::vector<cv::Point2f> out;
  cv::undistortPoints(in, out, K, camera.distortion, cv::noArray(), K);
  return {out[0].x, out[0].y};
}

}  // namespace mocap::camera
