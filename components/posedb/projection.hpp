#pragma once
// Perspective projection of a 15-joint body through a virtual camera.

#include <array>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/body15.hpp"
#include "posedb/view_set.hpp"

namespace mocap::posedb {

// Projects root-relative joints (metres, person facing +Z) with a pinhole of focal length 1
// (the scale does not matter after normalisation). Points behind the camera become NaN.
void project_body(const std::array<glm::vec3, kBodyJoints>& joints, const CameraPose& camera,
                  std::array<glm::vec2, kBodyJoints>& out);

}  // namespace mocap::posedb
