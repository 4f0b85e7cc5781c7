#include "recon/ray_alignment.hpp"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace mocap::recon {

Pinhole Pinhole::from_fov(int width, int height, float hfov_deg) {
  const float f = 0.5f * static_cast<float>(width) / std::tan(glm::radians(hfov_deg) / 2.0f);
  return {f, f, 0.5f * static_cast<float>(width), 0.5f * static_cast<float>(height)};
}

Pinhole pinhole_of(const camera::Camera& camera) {
  return {static_cast<float>(camera.fx), static_cast<float>(camera.fy),
          static_cast<float>(camera.cx), static_cast<float>(camera.cy)};
}

glm::quat ray_alignment(const camera::Camera& camera, glm::vec2 root_pixel) {
  // In float, as the poses it turns.
  const Pinhole pinhole = pinhole_of(camera);
  if (!pinhole.valid() || !std::isfinite(root_pixel.x) || !std::isfinite(root_pixel.y))
    return {1, 0, 0, 0};
  // The look-at frame's axes in the real camera's coordinates (x right, y down, z forward).
  const glm::vec3 forward = glm::normalize(glm::vec3(
      (root_pixel.x - pinhole.cx) / pinhole.fx, (root_pixel.y - pinhole.cy) / pinhole.fy, 1.0f));
  const glm::vec3 up(0.0f, -1.0f, 0.0f);
  const glm::vec3 right = glm::normalize(glm::cross(forward, up));
  const glm::vec3 down = glm::cross(forward, right);
  // Columns: where the look-at frame's x, y, z axes point in the real camera.
  return glm::quat_cast(glm::mat3(right, down, forward));
}

}  // namespace mocap::recon
