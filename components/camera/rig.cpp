#include "camera/rig.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

namespace mocap::camera {

const Camera* Rig::find(std::string_view name) const {
  const auto found = index_of(name);
  return found ? &cameras[*found] : nullptr;
}

std::optional<std::size_t> Rig::index_of(std::string_view name) const {
  for (std::size_t i = 0; i < cameras.size(); ++i)
    if (cameras[i].name == name) return i;
  return std::nullopt;
}

std::optional<GroundPlane> Rig::floor_in_camera(std::size_t index) const {
  if (!floor || index >= cameras.size()) return std::nullopt;
  return transformed(*floor, cameras[index].rotation, cameras[index].translation);
}

std::string ground_problem(const GroundPlane& p) {
  const glm::dvec3& n = p.normal;
  if (!(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z)))
    return "normal has a non-finite value";
  const double length = glm::length(n);
  if (length < 1e-9) return "normal is the zero vector";
  if (std::abs(length - 1.0) > 1e-3)
    return "normal must be a unit vector, its length is " + std::to_string(length);
  if (!std::isfinite(p.offset)) return "offset is not finite";
  return {};
}

std::optional<glm::dvec3> cameras_up(const Rig& rig) {
  glm::dvec3 up(0.0);
  // Row 1 of R (world -> camera) is the camera's y axis in the world.
  for (const Camera& c : rig.cameras)
    up -= glm::dvec3(c.rotation[0][1], c.rotation[1][1], c.rotation[2][1]);
  const double length = glm::length(up);
  if (!(length > 1e-9) || !std::isfinite(length)) return std::nullopt;
  return up / length;
}

std::string rig_problem(const Rig& rig) {
  if (rig.cameras.empty()) return "no camera";
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    const Camera& c = rig.cameras[i];
    const std::string which =
        c.name.empty() ? "camera " + std::to_string(i + 1) : "camera '" + c.name + "'";
    if (const std::string p = camera_problem(c); !p.empty()) return which + " " + p;
    for (std::size_t j = 0; j < i; ++j)
      if (rig.cameras[j].name == c.name) return "two cameras are named '" + c.name + "'";
  }
  if (rig.floor)
    if (const std::string p = ground_problem(*rig.floor); !p.empty()) return "the floor's " + p;
  return {};
}

namespace {

bool close(double a, double b, double tolerance) {
  if (a == b) return true;  // infinities too
  return std::abs(a - b) <= tolerance * std::max({1.0, std::abs(a), std::abs(b)});
}

bool close3(const glm::dvec3& a, const glm::dvec3& b, double tolerance) {
  return close(a.x, b.x, tolerance) && close(a.y, b.y, tolerance) && close(a.z, b.z, tolerance);
}

bool cameras_match(const Camera& a, const Camera& b, double tolerance) {
  if (a.name != b.name || a.width != b.width || a.height != b.height || a.fisheye != b.fisheye)
    return false;
  if (!close(a.fx, b.fx, tolerance) || !close(a.fy, b.fy, tolerance) ||
      !close(a.cx, b.cx, tolerance) || !close(a.cy, b.cy, tolerance))
    return false;
  const std::size_t n = std::max(a.distortion.size(), b.distortion.size());
  for (std::size_t i = 0; i < n; ++i) {
    const double da = i < a.distortion.size() ? a.distortion[i] : 0.0;
    const double db = i < b.distortion.size() ? b.distortion[i] : 0.0;
    if (!close(da, db, tolerance)) return false;
  }
  for (int c = 0; c < 3; ++c)
    if (!close3(a.rotation[c], b.rotation[c], tolerance)) return false;
  return close3(a.translation, b.translation, tolerance);
}

}  // namespace

bool rigs_match(const Rig& a, const Rig& b, double tolerance) {
  if (a.cameras.size() != b.cameras.size() || a.floor.has_value() != b.floor.has_value())
    return false;
  for (std::size_t i = 0; i < a.cameras.size(); ++i)
    if (!cameras_match(a.cameras[i], b.cameras[i], tolerance)) return false;
  return !a.floor || (close3(a.floor->normal, b.floor->normal, tolerance) &&
                      close(a.floor->offset, b.floor->offset, tolerance));
}

double baseline_m(const Camera& a, const Camera& b) { return glm::length(a.centre() - b.centre()); }

double axis_angle_deg(const Camera& a, const Camera& b) {
  const double c = std::clamp(glm::dot(a.optical_axis(), b.optical_axis()), -1.0, 1.0);
  return std::acos(c) * 180.0 / std::numbers::pi;
}

double height_above_m(const Camera& c, const GroundPlane& world_floor) {
  return world_floor.height_of(c.centre());
}

double tilt_below_horizon_deg(const Camera& c, const GroundPlane& world_floor) {
  const double down = std::clamp(-glm::dot(world_floor.normal, c.optical_axis()), -1.0, 1.0);
  return std::asin(down) * 180.0 / std::numbers::pi;
}

}  // namespace mocap::camera
