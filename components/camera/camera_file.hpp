#pragma once
// The single-camera file: OpenCV YAML as OpenCV's own calibration writes it (image_width,
// image_height, camera_matrix, distortion_coefficients), optionally avg_reprojection_error and the
// floor as the camera sees it (ground_normal, ground_offset; `mocap calibrate ground`). It is a
// rig file too (rig_file.hpp): one camera whose frame is the world. The monocular pipeline's
// `camera` parameters read any rig file of one camera (this one, or a TOML or YAML rig) through
// these functions.

#include <optional>
#include <string>

#include "camera/camera.hpp"
#include "core/ground_plane.hpp"

namespace mocap::camera {

// The camera of a rig file that has exactly one. Throws mocap::InputError naming the file (see
// rig_file.hpp; also for a rig of several cameras).
Camera read_camera_file(const std::string& path);

// The floor of a one-camera rig file in that camera's frame (x right, y down, z forward; the
// offset is the camera's height above the floor), std::nullopt when the file has none. Throws
// InputError as read_camera_file.
std::optional<GroundPlane> read_ground_plane(const std::string& path);

// Writes the single-camera file (OpenCV YAML): the camera's intrinsics (no distortion is written
// as five zeros; not its name or pose: it reads back as kDefaultCamera at the world origin),
// `rms_px` >= 0 as avg_reprojection_error, a ground plane (camera frame) as ground_normal and
// ground_offset. Throws InputError naming the file when it cannot be written; std::invalid_argument
// for a camera or plane that the reader would refuse.
void write_camera_file(const std::string& path, const Camera& camera, double rms_px = -1.0,
                       const std::optional<GroundPlane>& ground = {});

// Gives the one-camera rig file `path` the floor `plane` (camera frame): a single-camera file is
// rewritten with its intrinsics and avg_reprojection_error, a rig file with the floor in its
// world. Throws InputError naming the file when it is not a one-camera rig file or cannot be
// written; std::invalid_argument for a plane that is not finite or whose normal is not a unit
// vector. A failed write leaves the old file as it was.
void write_ground_plane(const std::string& path, const GroundPlane& plane);

}  // namespace mocap::camera
