#pragma once
// Camera intrinsics and their files: OpenCV YAML as OpenCV's own calibration writes them
// (camera_matrix, distortion_coefficients, image_width, image_height).

#include <array>
#include <string>
#include <vector>

namespace mocap::camera {

struct CameraIntrinsics {
  int width = 0;
  int height = 0;
  // Row-major 3x3 camera matrix [fx 0 cx; 0 fy cy; 0 0 1].
  std::array<double, 9> K{};
  // OpenCV distortion coefficients (k1 k2 p1 p2 [k3 [k4 k5 k6 [s1..s4 [tx ty]]]]); may be empty.
  std::vector<double> distortion;

  double fx() const { return K[0]; }
  double fy() const { return K[4]; }
  double cx() const { return K[2]; }
  double cy() const { return K[5]; }
  bool operator==(const CameraIntrinsics&) const = default;
};

// A pinhole camera without distortion whose horizontal field of view is `hfov_deg` (0 < hfov < 180)
// with the principal point at the image centre, square pixels and five zero distortion
// coefficients. Throws std::invalid_argument for
// a non-positive size or a field of view outside (0, 180).
CameraIntrinsics from_fov(int width, int height, double hfov_deg);

// Reads a camera file. Throws mocap::InputError naming the file (and the key, when one is missing
// or malformed) for a missing, empty, truncated or unparsable file, a missing key, a wrong matrix
// shape or non-finite / non-positive values.
CameraIntrinsics read_camera_file(const std::string& path);

// Writes a camera file (OpenCV YAML); an empty distortion is written as five zeros. `rms_px` >= 0
// is written as avg_reprojection_error. Throws mocap::InputError naming the file when it cannot be
// written.
void write_camera_file(const std::string& path, const CameraIntrinsics& camera,
                       double rms_px = -1.0);

}  // namespace mocap::camera
