#include "posedb/projection.hpp"

#include <limits>

#include <glm/mat3x3.hpp>

namespace mocap::posedb {

void project_body(const std::array<glm::vec3, kBodyJoints>& joints, const camera::Camera& camera,
                  std::array<glm::vec2, kBodyJoints>& out) {
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  const glm::mat3 rotation(camera.rotation);
  const glm::vec3 translation(camera.translation);
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  for (int j = 0; j < kBodyJoints; ++j) {
    const glm::vec3 c = rotation * joints[j] + translation;
    out[j] =
        c.z > 1e-3f ? glm::vec2(fx * c.x / c.z + cx, fy * c.y / c.z + cy) : glm::vec2(nan, nan);
  }
}

}  // namespace mocap::posedb
