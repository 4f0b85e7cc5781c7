#pragma once
// Where people stand when the scene is drawn (the overlay's 3D panel, the browser viewer): a
// placed person (Person3D::placed) where the fitting put them, an unplaced (root-relative) one at
// a display spot, in a row in front of the camera on the floor.

#include <cstddef>

#include <glm/vec3.hpp>

#include "core/messages.hpp"

namespace mocap {

// The floor assumed when it is not known: level, 1.5 m below the camera.
GroundPlane assumed_ground();

// Where the root of the `slot`-th of `count` unplaced people is drawn: 3 m in front of the camera,
// `spacing_m` apart left to right, hips 0.95 m above `ground` (the known floor or
// assumed_ground()).
glm::vec3 display_root(const GroundPlane& ground, std::size_t slot, std::size_t count,
                       float spacing_m = 0.8f);

}  // namespace mocap
