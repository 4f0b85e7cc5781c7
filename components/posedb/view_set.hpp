#pragma once
// The virtual cameras the database projects every mocap frame through: yaw steps around the
// person and, beyond the paper, several camera heights so that a camera looking down works too.

#include <string>
#include <vector>

#include "camera/camera.hpp"

namespace mocap::posedb {

// One virtual camera, placed relative to a person who faces +Z with the root at the origin.
struct View {
  float yaw_deg =
      0.0f;  // camera azimuth around the person: 0 = in front, 90 = at the person's left
  float height_m = 1.5f;    // camera height above the floor
  float distance_m = 4.0f;  // horizontal distance from the person
  float pitch_deg =
      0.0f;  // derived: downward angle of the line of sight to the root (positive = down)
};

struct ViewSetOptions {
  int yaw_steps = 30;                                       // 12 degree steps, as the paper
  std::vector<float> heights_m = {1.5f, 2.5f, 4.0f, 6.0f};  // 1.5 m is the paper's camera
  float distance_m = 4.0f;
  // Height of the root (mid-hips) above the floor that camera heights are measured against.
  float root_height_m = 0.95f;
};

std::vector<View> make_views(const ViewSetOptions& options);

// The virtual camera of a view: looking at the root (at the origin), image x right, y down, z
// forward as OpenCV, focal length 1 and principal point 0 (the normalised image; the scale does
// not matter after normalisation), no image size. Throws std::invalid_argument for a camera
// straight above the root (no yaw is defined).
camera::Camera view_camera(const View& view, float root_height_m);

}  // namespace mocap::posedb
