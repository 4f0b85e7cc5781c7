#include "recon/ray_alignment.hpp"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace mocap::recon {

Pinhole Pinhole::from_fov(int width, int height, float hfov_deg) {
  const float f = 0.5f * static_cast<float>(width) / std::tan(glm::radians(hfov_deg) / 2.0f);
  return {f, f, 0.5f * static_cast<float>(width), 0.5f * static_cast<float>(height)};
}

glm::quat ray_alignment(const Pinhole& camera, glm::vec2 root_pixel) {
  if (!camera.valid() || !std::isfinite(root_pixel.x) || !std::isfinite(root_pixel.y))
    return {1, 0, 0, 0};
  // The look-at frame's axes in the real camera's coordinates (x right, y down, z forward).
  const glm::vec3 forward = glm::normalize(glm::vec3((root_pixel.x - camera.cx) / camera.fx,
                                                     (root_pixel.y - camera.cy) / camera.fy, 1.0f));
  const glm::vec3 up(0.0f, -1.0f, 0.0f);
  const glm::vec3 right = glm::normalize(glm::cross(forward, up));
  const glm::vec3 down = glm::cross(forward, right);
  // Columns: where the look-at frame's x, y, z axes point in the real camera.
  return glm::quat_cast(glm::mat3(right, down, forward));
}

}  // namespace mocap::recon
