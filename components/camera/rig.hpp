#pragma once
// A rig: N named cameras posed in one world, and its floor (docs/cameras.md). Metres throughout.
// The files: camera/rig_file.hpp (Pose2Sim/anipose TOML, OpenCV YAML).

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "camera/camera.hpp"
#include "core/ground_plane.hpp"

namespace mocap::camera {

struct Rig {
  std::vector<Camera> cameras;       // in file order; names unique
  std::optional<GroundPlane> floor;  // in the world frame, when known

  const Camera* find(std::string_view name) const;
  std::optional<std::size_t> index_of(std::string_view name) const;
  // The floor in camera `index`'s frame (its height above the floor is the plane's offset).
  std::optional<GroundPlane> floor_in_camera(std::size_t index) const;

  bool operator==(const Rig&) const = default;
};

// Which way is up, judged from the cameras alone (they are mounted upright: their image y axis
// points down in the world): the unit mean of their up directions, or nullopt without cameras
// or when those cancel out. For a rig without a floor.
std::optional<glm::dvec3> cameras_up(const Rig& rig);

// Why the rig cannot be used (no camera, a camera_problem(), a name used twice, a floor whose
// normal is not a unit vector or that is not finite), or empty. The answer names the camera.
std::string rig_problem(const Rig& rig);
// Why the plane cannot be a floor (non-finite, a normal not of unit length within 1e-3), or empty;
// the answer starts with the field at fault: "normal ..." or "offset ...".
std::string ground_problem(const GroundPlane& plane);

// Whether two rigs are the same up to `tolerance` (relative to each value's size, at least 1):
// names, sizes and flags equal, the numbers close, a missing distortion equal to zeros. What a
// rig written and read back must be.
bool rigs_match(const Rig& a, const Rig& b, double tolerance = 1e-9);

// Geometry between cameras and above the floor.
double baseline_m(const Camera& a, const Camera& b);      // distance between the centres
double axis_angle_deg(const Camera& a, const Camera& b);  // angle between the optical axes
double height_above_m(const Camera& c, const GroundPlane& world_floor);
// How far the optical axis points below the horizon of the floor, degrees (negative: above).
double tilt_below_horizon_deg(const Camera& c, const GroundPlane& world_floor);

}  // namespace mocap::camera
