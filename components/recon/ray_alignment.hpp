#pragma once
// Every database camera looks straight at the person's root; a real camera sees the person
// somewhere off its optical axis, along the ray through the root's pixel. A pose taken from the
// database is therefore turned from the "looking at the root" frame into the real camera's frame,
// or every joint is off by the angle between the optical axis and that ray (7-25° for a person
// in a corner of a wide view).

#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>

#include "camera/camera.hpp"

namespace mocap::recon {

// The rotation taking a pose expressed in a camera that looks at the root (x horizontal) into the
// frame of `camera`, which sees the root at `root_pixel` (undistorted: the pinhole's pixel).
// Assumes the camera has no roll (its x axis horizontal), as the database's cameras. Identity
// for a camera without intrinsics.
glm::quat ray_alignment(const camera::Camera& camera, glm::vec2 root_pixel);

}  // namespace mocap::recon
