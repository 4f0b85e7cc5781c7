#include "camera/undistortion.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/calib3d.hpp>

namespace mocap::camera {

std::array<float, 2> undistort_pixel(const CameraIntrinsics& camera, float x, float y) {
  std::array<float, 2> pixel{x, y};
  undistort_pixels(camera, {&pixel, 1});
  return pixel;
}

void undistort_pixels(const CameraIntrinsics& camera, std::span<std::array<float, 2>> pixels) {
  const bool distorted = std::any_of(camera.distortion.begin(), camera.distortion.end(),
                                     [](double d) { return d != 0.0; });
  if (!distorted) return;
  std::vector<cv::Point2f> in;
  in.reserve(pixels.size());
  for (const auto& [x, y] : pixels)
    if (std::isfinite(x) && std::isfinite(y)) in.emplace_back(x, y);
  if (in.empty()) return;
  const cv::Matx33d K(camera.K.data());
  std::vector<cv::Point2f> out;
  cv::undistortPoints(in, out, K, camera.distortion, cv::noArray(), K);
  std::size_t next = 0;
  for (auto& [x, y] : pixels) {
    if (!std::isfinite(x) || !std::isfinite(y)) continue;  // non-finite input stays as it is
    x = out[next].x;
    y = out[next].y;
    ++next;
  }
}

}  // namespace mocap::camera
