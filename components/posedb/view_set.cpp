#include "posedb/view_set.hpp"

#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/trigonometric.hpp>

namespace mocap::posedb {

camera::Camera view_camera(const View& view, float root_height_m) {
  const float yaw = glm::radians(view.yaw_deg);
  // Yaw 0: the camera stands on the +Z axis, in front of a person who faces +Z.
  const glm::vec3 position(view.distance_m * std::sin(yaw), view.height_m - root_height_m,
                           view.distance_m * std::cos(yaw));
  const glm::vec3 forward = glm::normalize(-position);  // towards the root at the origin
  const glm::vec3 world_up(0.0f, 1.0f, 0.0f);
  glm::vec3 right = glm::cross(forward, world_up);
  if (glm::length(right) < 1e-6f)
    throw std::invalid_argument("camera looks straight down: no yaw is defined");
  right = glm::normalize(right);
  const glm::vec3 down = glm::cross(forward, right);
  // Rows of the world-to-camera matrix are the camera axes expressed in the world.
  glm::mat3 m;
  m[0] = glm::vec3(right.x, down.x, forward.x);
  m[1] = glm::vec3(right.y, down.y, forward.y);
  m[2] = glm::vec3(right.z, down.z, forward.z);
  camera::Camera camera;
  camera.name = "view";
  camera.fx = camera.fy = 1.0;
  camera.rotation = glm::dmat3(m);
  camera.translation = -(camera.rotation * glm::dvec3(position));
  return camera;
}

std::vector<View> make_views(const ViewSetOptions& o) {
  if (o.yaw_steps < 1 || o.yaw_steps > 3600)
    throw std::invalid_argument("yaw steps must be 1 to 3600");
  if (o.heights_m.empty()) throw std::invalid_argument("at least one camera height is needed");
  if (!(o.distance_m > 0.1f)) throw std::invalid_argument("camera distance must be above 0.1 m");
  std::vector<View> views;
  for (float h : o.heights_m) {
    const float pitch = glm::degrees(std::atan2(h - o.root_height_m, o.distance_m));
    for (int y = 0; y < o.yaw_steps; ++y) {
      views.push_back({360.0f * static_cast<float>(y) / static_cast<float>(o.yaw_steps), h,
                       o.distance_m, pitch});
    }
  }
  return views;
}

}  // namespace mocap::posedb
