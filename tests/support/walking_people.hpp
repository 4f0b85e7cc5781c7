#pragma once
// Synthetic people for the viewer's tests and benchmark: a body facing the camera (root-relative,
// camera frame: x right, y down, z forward, metres) whose arms and legs swing with `phase`
// (radians), and its keypoints through a 640x480 pinhole when it stands at `at`.

#include <cmath>

#include "core/messages.hpp"

namespace mocap::test {

inline Person3D walking_person(int id, float phase, glm::vec3 at = {0.0f, 0.0f, 3.0f}) {
  Person3D p;
  p.id = id;
  const float s = 0.25f * std::sin(phase);
  auto set = [&](Joint j, float x, float y, float z) { p.positions[index(j)] = {x, y, z}; };
  set(Joint::root, 0, 0, 0);
  set(Joint::neck, 0, -0.5f, 0);
  set(Joint::head, 0, -0.72f, 0);
  set(Joint::right_shoulder, -0.18f, -0.47f, 0);
  set(Joint::right_elbow, -0.21f, -0.2f, s);
  set(Joint::right_wrist, -0.23f, 0.05f, 1.6f * s);
  set(Joint::left_shoulder, 0.18f, -0.47f, 0);
  set(Joint::left_elbow, 0.21f, -0.2f, -s);
  set(Joint::left_wrist, 0.23f, 0.05f, -1.6f * s);
  set(Joint::right_hip, -0.1f, 0, 0);
  set(Joint::right_knee, -0.1f, 0.45f, -s);
  set(Joint::right_ankle, -0.1f, 0.9f, -1.4f * s);
  set(Joint::left_hip, 0.1f, 0, 0);
  set(Joint::left_knee, 0.1f, 0.45f, s);
  set(Joint::left_ankle, 0.1f, 0.9f, 1.4f * s);
  for (int j = 0; j < kBodyJoints; ++j) {
    const glm::vec3 c = p.positions[static_cast<std::size_t>(j)] + at;
    p.keypoints[static_cast<std::size_t>(j)] = {320.0f + 554.0f * c.x / c.z,
                                                240.0f + 554.0f * c.y / c.z, 0.9f};
  }
  return p;
}

// `count` people with ids 1..count at frame `frame` (each with its own phase).
inline People3D walking_people(int count, std::int64_t frame, double fps = 30.0) {
  People3D out;
  out.header.frame = frame;
  out.header.seq = static_cast<std::uint64_t>(frame);
  out.header.capture_ns = static_cast<std::int64_t>(static_cast<double>(frame) / fps * 1e9);
  for (int i = 0; i < count; ++i) {
    const float x = (static_cast<float>(i) - 0.5f * static_cast<float>(count - 1)) * 0.8f;
    out.people.push_back(walking_person(
        i + 1, static_cast<float>(frame) * 0.2f + static_cast<float>(i), {x, 0.3f, 3.0f}));
  }
  return out;
}

}  // namespace mocap::test
