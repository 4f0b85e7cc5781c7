#pragma once
// The virtual cameras the database projects every mocap frame through: yaw steps around the
// person and, beyond the paper, several camera heights so that a camera looking down works too.

#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

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

// World-to-camera rotation and camera position for a view (camera looks at the root; image x
// right, y down, z forward as OpenCV).
struct CameraPose {
  glm::quat world_to_camera;
  glm::vec3 position;
};
CameraPose camera_pose(const View& view, float root_height_m);

}  // namespace mocap::posedb
