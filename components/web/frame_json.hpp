#pragma once
// The viewer's messages: People3D -> one compact JSON text per frame (docs/viewer.md):
//   {"type":"frame","frame":12,"time":0.48,
//    "people":[{"id":3,"placed":false,"joints":[x,y,z, ...15 joints, millimetres],
//               "keypoints":[x,y,c, ...15 joints, pixels and confidence]}],
//    "ground":{"known":true,"normal":[x,y,z],"offset":1.52},
//    "camera":{"known":true,"assumed":false,"width":640,"height":480,"fx":..,"fy":..,"cx":..,"cy":..},
//    "playback":{"index":5,"count":795,"playing":true,"speed":1,"duration":26.5}}   (recordings)
// Joints are absolute camera-frame positions (x right, y down, z forward): a placed person's own,
// an unplaced (root-relative) person's shifted to a display spot (core/scene.hpp: display_root,
// 0.8 m apart) so that everyone stands on the floor in a row in front of the camera; the floor is
// assumed_ground() when it is not known.

#include <cstddef>
#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "camera/camera.hpp"
#include "core/messages.hpp"
#include "core/scene.hpp"

namespace mocap::web {

// The camera the page draws, when known: its frustum from the intrinsics.
struct ShownCamera {
  camera::Camera camera;
  bool assumed = false;  // from a field of view, not calibrated
};

struct Playback {
  std::size_t index = 0, count = 0;
  bool playing = true;
  double speed = 1.0;
  double duration = 0.0;  // seconds
};

// The greeting each browser gets first: joint names and the bones (pairs of joint indices).
std::string hello_json(const std::string& title);

std::string frame_json(const People3D& frame, const std::optional<ShownCamera>& camera,
                       const std::optional<Playback>& playback = std::nullopt,
                       std::optional<double> time = std::nullopt);

}  // namespace mocap::web
