#include "recon/ray_alignment.hpp"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace mocap::recon {

glm::quat ray_alignment(const camera::Camera& camera, glm::vec2 root_pixel) {
  if (!camera.has_intrinsics() || !std::isfinite(root_pixel.x) || !std::isfinite(root_pixel.y))
    return {1, 0, 0, 0};
  // In float, as the poses it turns.
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  // The look-at frame's axes in the real camera's coordinates (x right, y down, z forward).
  const glm::vec3 forward =
      glm::normalize(glm::vec3((root_pixel.x - cx) / fx, (root_pixel.y - cy) / fy, 1.0f));
  const glm::vec3 up(0.0f, -1.0f, 0.0f);
  const glm::vec3 right = glm::normalize(glm::cross(forward, up));
  const glm::vec3 down = glm::cross(forward, right);
  // Columns: where the look-at frame's x, y, z axes point in the real camera.
  return glm::quat_cast(glm::mat3(right, down, forward));
}

}  // namespace mocap::recon
