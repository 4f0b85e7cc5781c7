#pragma once
// The floor: one type for every module (messages, the rig, camera files, the viewer, the BVH).
// GLM only, so that core/messages.hpp can carry it.

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace mocap {

// The points x with dot(normal, x) + offset = 0, metres. `normal` is a unit vector pointing up
// (away from the floor), so dot(normal, p) + offset is the height of p above the floor.
//
// The plane is in the frame of what holds it, which says which frame that is: a People3D's
// `frame` (a camera's, x right, y down, z forward, or the rig's world), a rig's world
// (camera::Rig::floor), a single-camera file's camera. In a camera's frame the camera centre is
// the origin, so `offset` is the camera's height above the floor.
struct GroundPlane {
  glm::dvec3 normal{0.0, -1.0, 0.0};  // level, for a camera frame (y down)
  double offset = 0.0;

  double height_of(const glm::dvec3& point) const { return glm::dot(normal, point) + offset; }
  bool operator==(const GroundPlane&) const = default;
};

// The same plane in another frame, given the transform into it: x' = rotation · x + translation.
inline GroundPlane transformed(const GroundPlane& plane, const glm::dmat3& rotation,
                               const glm::dvec3& translation) {
  // n·x + d = 0 with x = Rᵀ(x' − t):  (R n)·x' + d − (R n)·t = 0.
  const glm::dvec3 normal = rotation * plane.normal;
  return {normal, plane.offset - glm::dot(normal, translation)};
}

}  // namespace mocap
