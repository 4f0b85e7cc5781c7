#include "core/scene.hpp"

#include <glm/geometric.hpp>

namespace mocap {

GroundPlane assumed_ground() { return GroundPlane{{0.0, -1.0, 0.0}, 1.5}; }

glm::vec3 display_root(const GroundPlane& ground, std::size_t slot, std::size_t count,
                       float spacing_m) {
  const float x = (static_cast<float>(slot) - 0.5f * static_cast<float>(count - 1)) * spacing_m;
  const glm::vec3 ahead(x, 0.0f, 3.0f);
  const glm::vec3 normal(ground.normal);  // the plane is in double, the display in float
  const glm::vec3 on_floor =
      ahead - (glm::dot(normal, ahead) + static_cast<float>(ground.offset)) * normal;
  return on_floor + 0.95f * normal;
}

}  // namespace mocap
