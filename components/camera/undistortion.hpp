#pragma once
// Where a pixel of a distorted image would be seen by the same camera without lens distortion:
// what the ray through a detected keypoint needs when the camera file has distortion terms.

#include <array>

#include "camera/camera_file.hpp"

namespace mocap::camera {

// The undistorted pixel (same camera matrix) of pixel (x, y). Identity when the camera has no
// distortion; non-finite input comes back unchanged.
std::array<float, 2> undistort_pixel(const CameraIntrinsics& camera, float x, float y);

}  // namespace mocap::camera
