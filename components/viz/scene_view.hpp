#pragma once
// The overlay's 3D panel as geometry, without drawing: where every person stands in the scene and
// the virtual camera that shows them.
//
// People are placed by the fitting's root translation (Person3D::placed, camera frame) on the
// frame's floor (People3D::ground when known); people without a translation are stood upright on
// the floor in a row in front of the camera (core/scene.hpp display_root). A virtual camera,
// orthographic, with the floor's up as the picture's up, turned about the vertical from the real
// camera's view and looking down, frames them all: its framing grows at once to take in a person
// who would leave the panel and shrinks slowly when people go, so the view does not jump.

#include <array>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/messages.hpp"

namespace mocap::viz {

struct ScenePerson {
  int id = -1;
  bool placed = false;                          // by the fitting; else a display spot in a row
  std::array<glm::vec3, kBodyJoints> joints{};  // camera frame, metres; NaN where unknown
};

// The floor the picture stands people on: the frame's own when known; else level (the image's
// up) under the lowest foot of the placed people; else core's assumed_ground().
GroundPlane scene_floor(const People3D& people);

// Every person of `people` in the scene, on `floor`. The unplaced ones stand `spacing_m` apart in
// the order of their boxes in the 2D input, left to right (people without a box after them, by
// id), upright on the floor.
std::vector<ScenePerson> scene_people(const People3D& people, const People2D& people2d,
                                      const GroundPlane& floor, float spacing_m);

// A person's joints turned so that their body's up is `up` (camera frame): a camera looking down
// (a high database view) sees a standing person tilted; the tilt is removed, the facing kept.
// The body's up is root.rotation * +Y (root.rotation: body frame, y up, to camera); positions
// are kept as they are when that rotation was not set (its up pointing away from `up`).
std::array<glm::vec3, kBodyJoints> upright_positions(const Person3D& person,
                                                     glm::vec3 up = {0.0f, -1.0f, 0.0f});

// The virtual camera of a panel of `width` x `height` pixels (its top `top` pixels kept for the
// title).
class SceneCamera {
 public:
  SceneCamera(int width, int height, int top, float yaw_deg, float pitch_deg);

  // Sets the floor and moves the framing towards the people of the next frame (called once per
  // frame, in order; without people the framing stays).
  void follow(const GroundPlane& floor, const std::vector<ScenePerson>& people);

  // A camera-frame point (metres) in the panel (pixels), and how far it is from the virtual
  // camera (larger: farther; for drawing the far people first).
  glm::vec2 project(glm::vec3 camera_point) const;
  float depth(glm::vec3 camera_point) const;
  // The same for a point given on the floor's axes: x to the right of the real camera, height
  // above the floor, distance ahead of the real camera along the floor.
  glm::vec2 project_floor(glm::vec3 x_height_ahead) const;
  // The floor's axes (x, height, ahead) of a camera-frame point.
  glm::vec3 floor_coordinates(glm::vec3 camera_point) const;
  // The part of the floor (x and ahead, metres) the panel shows: {min x, min ahead, max x, max
  // ahead}, each rounded out to `step`.
  std::array<float, 4> visible_floor(float step) const;
  float pixels_per_metre() const;
  const GroundPlane& floor() const { return floor_; }

 private:
  glm::vec3 view_of(glm::vec3 x_height_ahead) const;  // view axes: x right, y down, z away

  int width_, height_, top_;
  float yaw_, pitch_;
  GroundPlane floor_;
  glm::vec3 right_{1, 0, 0}, up_{0, -1, 0}, ahead_{0, 0, 1};
  bool framed_ = false;
  glm::vec2 low_{0.0f}, high_{0.0f};  // framed view rectangle, metres
};

}  // namespace mocap::viz
