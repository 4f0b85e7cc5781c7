#pragma once
// Where a pixel of a distorted image would be seen by the same camera without lens distortion:
// what the ray through a detected keypoint needs when the camera file has distortion terms.

#include <array>
#include <span>

#include "camera/camera_file.hpp"

namespace mocap::camera {

// The undistorted pixel (same camera matrix) of pixel (x, y). Identity when the camera has no
// distortion; non-finite input comes back unchanged.
std::array<float, 2> undistort_pixel(const CameraIntrinsics& camera, float x, float y);

// The same for many pixels in place, with one OpenCV call (a person's keypoints per frame).
void undistort_pixels(const CameraIntrinsics& camera, std::span<std::array<float, 2>> pixels);

}  // namespace mocap::camera
