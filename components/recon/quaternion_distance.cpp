#include "recon/quaternion_distance.hpp"

#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

namespace mocap::recon {
namespace {

// Below this length a direction is treated as undefined (metres or any other unit: bones of real
// bodies are many orders of magnitude longer).
constexpr float kTinyLength = 1e-12f;
// |from + to| below this (unit vectors) means the directions are opposite to float precision.
constexpr float kOppositeTolerance = 1e-6f;

glm::vec3 perpendicular_axis(const glm::vec3& unit) {
  glm::vec3 axis = glm::vec3(0, 0, 1) - unit.z * unit;
  if (glm::length(axis) < 0.1f) axis = glm::vec3(1, 0, 0) - unit.x * unit;
  return glm::normalize(axis);
}

bool usable_direction(const glm::vec3& v, float length) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && length > kTinyLength;
}

}  // namespace

float quaternion_distance(const glm::quat& q1, const glm::quat& q2) {
  // The conjugate equals the inverse up to a positive scale, which atan2 ignores.
  const glm::quat r = glm::conjugate(q1) * q2;
  const float vector_norm = std::sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
  // |w| folds −r onto r: a rotation and its negated quaternion are one rotation.
  return 2.0f * std::atan2(vector_norm, std::abs(r.w));
}

float pose_distance(std::span<const glm::quat> a, std::span<const glm::quat> b,
                    std::span<const float> weights) {
  if (a.size() != b.size() || a.size() != weights.size()) {
    throw std::invalid_argument("pose_distance: poses and weights differ in size");
  }
  float sum = 0.0f;
  for (std::size_t j = 0; j < a.size(); ++j) {
    if (weights[j] == 0.0f) continue;  // skips the atan2 of bones that do not count
    const float d = quaternion_distance(a[j], b[j]);
    sum += weights[j] * d * d;
  }
  return sum;
}

glm::quat swing_rotation(const glm::vec3& from, const glm::vec3& to) {
  const float from_length = glm::length(from);
  const float to_length = glm::length(to);
  if (!usable_direction(from, from_length) || !usable_direction(to, to_length)) {
    return glm::quat(1, 0, 0, 0);
  }
  const glm::vec3 a = from / from_length;
  const glm::vec3 b = to / to_length;
  const glm::vec3 half = a + b;
  const float half_length = glm::length(half);
  if (half_length < kOppositeTolerance) return glm::quat(0.0f, perpendicular_axis(a));
  // With h the unit bisector of a and b, (a·h, a×h) = (cos θ/2, sin θ/2 · axis): the rotation by
  // the angle θ between a and b about their common normal. Stable for every θ short of π.
  const glm::vec3 h = half / half_length;
  return glm::quat(glm::dot(a, h), glm::cross(a, h));
}

BoneRotations bone_rotations(std::span<const glm::vec3, kBodyJoints> joints) {
  BoneRotations rotations;
  for (int bone = 0; bone < kBodyBones; ++bone) {
    const glm::vec3 direction = joints[bone] - joints[kJointParent[bone]];
    rotations[bone] = swing_rotation(kBoneRestDirection[bone], direction);
  }
  return rotations;
}

BoneRotations bone_rotations(std::span<const float, kBodyJoints * 3> joints) {
  std::array<glm::vec3, kBodyJoints> points;
  for (int j = 0; j < kBodyJoints; ++j) {
    points[j] = glm::vec3(joints[3 * j], joints[3 * j + 1], joints[3 * j + 2]);
  }
  return bone_rotations(points);
}

}  // namespace mocap::recon
