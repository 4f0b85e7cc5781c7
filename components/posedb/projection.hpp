#pragma once
// Perspective projection of a 15-joint body through a virtual camera.

#include <array>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "camera/camera.hpp"
#include "core/body15.hpp"

namespace mocap::posedb {

// Projects root-relative joints (metres, person facing +Z) through a view's camera (view_camera:
// focal length 1, no distortion), in float. Points behind the camera become NaN.
void project_body(const std::array<glm::vec3, kBodyJoints>& joints, const camera::Camera& camera,
                  std::array<glm::vec2, kBodyJoints>& out);

}  // namespace mocap::posedb
