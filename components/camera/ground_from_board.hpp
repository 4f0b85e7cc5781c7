#pragma once
// The floor from one image of a calibration board lying on it: the board's pose (solvePnP with
// the camera's intrinsics and lens distortion) gives the board's plane in the camera frame, which
// is the floor shifted up by the board's thickness.

#include <array>
#include <string>

#include "camera/board.hpp"
#include "camera/camera.hpp"
#include "core/ground_plane.hpp"

namespace mocap::camera {

struct FloorFromBoard {
  GroundPlane plane;  // camera frame; normal toward the camera's side of the floor (up)
  int corners = 0;    // board corners used for the pose
  double rms_px = 0;  // their reprojection error under the pose
  // The board pose (board frame -> camera frame, metres): Rodrigues vector and translation.
  std::array<double, 3> rotation{};
  std::array<double, 3> translation_m{};
};

// Finds the board in `image`, estimates its pose and returns the floor plane. Throws
// mocap::InputError naming the image when it cannot be read, its size differs from the camera's,
// the board is not found (the reason is given) or the camera lies in the board's plane;
// std::invalid_argument for a bad board, a negative thickness or a fisheye camera.
FloorFromBoard ground_from_board_image(const std::string& image, const Camera& camera,
                                       const BoardSpec& board, double board_thickness_mm = 0.0);

}  // namespace mocap::camera
