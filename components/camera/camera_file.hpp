#pragma once
// Camera intrinsics and their files: OpenCV YAML as OpenCV's own calibration writes them
// (camera_matrix, distortion_coefficients, image_width, image_height), optionally with the floor
// as seen by the camera (ground_normal, ground_offset; `mocap calibrate ground`).

#include <array>
#include <optional>
#include <string>
#include <string_view>
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

// The floor in the camera frame (x right, y down, z forward, metres): the points x with
// dot(normal, x) + offset = 0. `normal` is a unit vector pointing up, away from the floor, so the
// camera centre (the origin) is `offset` metres above the floor (offset > 0 for a camera above it).
struct GroundPlane {
  std::array<double, 3> normal{};
  double offset = 0.0;
  bool operator==(const GroundPlane&) const = default;
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
// The same from the text of a camera file; `name` stands for the file in messages.
CameraIntrinsics parse_camera_file(std::string_view text, const std::string& name);

// Writes a camera file (OpenCV YAML); an empty distortion is written as five zeros. `rms_px` >= 0
// is written as avg_reprojection_error, a ground plane as ground_normal and ground_offset. Throws
// mocap::InputError naming the file when it cannot be written; std::invalid_argument for a ground
// plane that read_ground_plane would reject.
void write_camera_file(const std::string& path, const CameraIntrinsics& camera,
                       double rms_px = -1.0, const std::optional<GroundPlane>& ground = {});

// Height of the camera centre above the floor in metres (= plane.offset).
double camera_height_m(const GroundPlane& plane);
// How far the optical axis points below the horizon, in degrees (negative: above it).
double camera_tilt_deg(const GroundPlane& plane);

// Reads the ground plane of a camera file: std::nullopt when the file has neither ground_normal
// nor ground_offset. Throws mocap::InputError naming the file (and the key) for a missing,
// empty or unparsable file, one of the two keys without the other, a normal that is not a 3-vector,
// not finite, zero or not of unit length (within 1e-3), or an offset that is not a finite number.
std::optional<GroundPlane> read_ground_plane(const std::string& path);
std::optional<GroundPlane> parse_ground_plane(std::string_view text, const std::string& name);

// Rewrites the camera file `path` with its intrinsics (and avg_reprojection_error when present)
// and the plane as ground_normal (3x1 matrix) and ground_offset (metres). Throws mocap::InputError
// naming the file when it is not a valid camera file or cannot be written; std::invalid_argument
// for a plane that is not finite or whose normal is not of unit length.
void write_ground_plane(const std::string& path, const GroundPlane& plane);

}  // namespace mocap::camera
