#include "posedb/projection.hpp"

#include <limits>

namespace mocap::posedb {

void project_body(const std::array<glm::vec3, kBodyJoints>& joints, const CameraPose& camera,
                  std::array<glm::vec2, kBodyJoints>& out) {
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  for (int j = 0; j < kBodyJoints; ++j) {
    const glm::vec3 c = camera.world_to_camera * (joints[j] - camera.position);
    out[j] = c.z > 1e-3f ? glm::vec2(c.x / c.z, c.y / c.z) : glm::vec2(nan, nan);
  }
}

}  // namespace mocap::posedb
