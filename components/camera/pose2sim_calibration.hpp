#pragma once
// Pose2Sim's calibration file (`Calib_*.toml`, OpenCV convention; see
// ../shared/data/eval/pose2sim_demo/README.md): one table per camera,
//
//   [cam_01]
//   name = "cam_01"
//   size = [ 1088.0, 1920.0]                      width, height in pixels
//   matrix = [ [fx, 0, cx], [0, fy, cy], [0, 0, 1]]
//   distortions = [ k1, k2, p1, p2]               OpenCV order
//   rotation = [ rx, ry, rz]                      Rodrigues vector, world -> camera
//   translation = [ tx, ty, tz]                   metres, world -> camera
//   fisheye = false
//
// and optionally a [metadata] table (ignored). Projection: x ~ K (R X_w + t), R = Rodrigues(r).
//
// The reader parses the TOML subset these files use (tables, `key = value` with strings,
// numbers, booleans and nested arrays that may span lines, `#` comments) with its own small
// parser; anything else, a missing or malformed key, a truncated or binary file is an InputError
// naming the file, the line and, where one applies, the table and the key.

#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "camera/camera_file.hpp"

namespace mocap::camera {

struct Pose2SimCamera {
  std::string section;          // the table's name: "cam_01"
  std::string name;             // its `name` key
  CameraIntrinsics intrinsics;  // size, matrix and distortions
  glm::dvec3 rotation{0.0};     // Rodrigues vector, world -> camera
  glm::dvec3 translation{0.0};  // metres, world -> camera
  bool fisheye = false;

  glm::dmat3 rotation_matrix() const;  // R: world -> camera (x_c = R x_w + t)
  glm::dvec3 to_camera(const glm::dvec3& world) const;
  glm::dvec3 centre() const;  // the camera centre in the world: -Rᵀ t
  // Pinhole projection (lens distortion ignored): pixels; depth <= 0 gives non-finite values.
  glm::dvec2 project(const glm::dvec3& world) const;
};

// The rotation matrix of a Rodrigues (angle-axis) vector.
glm::dmat3 rodrigues(const glm::dvec3& r);

// Every camera table in file order. Throws InputError (see above); a file without any camera
// table is an error too.
std::vector<Pose2SimCamera> read_pose2sim_calibration(const std::filesystem::path& file);
std::vector<Pose2SimCamera> parse_pose2sim_calibration(std::string_view text,
                                                       const std::string& file_name);

}  // namespace mocap::camera
