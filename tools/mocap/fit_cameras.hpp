#pragma once
// components/fit still takes its own camera types (recon::Pinhole, fit::CameraPose) while it is
// being rewritten; the commands that call it convert the one camera model into them here.

#include <glm/gtc/quaternion.hpp>
#include <glm/matrix.hpp>

#include "camera/camera.hpp"
#include "fit/skeleton_fit.hpp"

namespace mocap::cli {

// Where the camera is in the world (camera -> world), as fit::FrameInput takes it.
inline fit::CameraPose fit_camera_pose(const camera::Camera& camera) {
  return {glm::quat_cast(glm::transpose(camera.rotation)), camera.centre()};
}

}  // namespace mocap::cli
