#pragma once
// The viewer's messages: People3D -> one compact JSON text per frame (docs/viewer.md):
//   {"type":"frame","frame":12,"time":0.48,
//    "people":[{"id":3,"placed":false,"joints":[x,y,z, ...15 joints, millimetres],
//               "keypoints":[x,y,c, ...15 joints, pixels and confidence]}],
//    "ground":{"known":true,"normal":[x,y,z],"offset":1.52},
//    "camera":{"known":true,"assumed":false,"width":640,"height":480,"fx":..,"fy":..,"cx":..,"cy":..},
//    "playback":{"index":5,"count":795,"playing":true,"speed":1,"duration":26.5}}   (recordings)
// A world-frame message (a multi-view reconstruction) shown with its rig adds
//    "world":true,"up":[x,y,z],
//    "cameras":[{"name":"cam01","width":..,"height":..,"fx":..,"fy":..,"cx":..,"cy":..,
//                "rotation":[9 numbers, camera -> world, row-major],"position":[x,y,z metres]}]
// and its joints are world positions (the rig's axes); "camera" is then the rig's first camera
// (the 2D panel's frame).
// Joints are absolute camera-frame positions (x right, y down, z forward): a placed person's own,
// an unplaced (root-relative) person's shifted to a display spot (core/scene.hpp: display_root,
// 0.8 m apart) so that everyone stands on the floor in a row in front of the camera; the floor is
// assumed_ground() when it is not known.

#include <cstddef>
#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "camera/camera.hpp"
#include "camera/rig.hpp"
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

// A world-frame message with every camera of its rig at its pose. The floor: the message's, else
// the rig's, else (not known) level with the lowest ankle in view, or 1.6 m below the cameras.
// Up: the floor's normal, else opposite the cameras' mean "down" (cameras are mounted upright),
// else the people's hips-to-neck direction.
std::string frame_json(const People3D& frame, const camera::Rig& rig,
                       const std::optional<Playback>& playback = std::nullopt,
                       std::optional<double> time = std::nullopt);

}  // namespace mocap::web
