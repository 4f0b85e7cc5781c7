#pragma once
// Rig files (docs/cameras.md). Two formats, read and written:
//
// * TOML, the calibration layout Pose2Sim, anipose, Caliscope and FreeMoCap exchange: one table
//   per camera ([cam_01] ...) with `name`, `size` [width, height], `matrix` (3x3), `distortions`
//   (OpenCV order), `rotation` (Rodrigues vector, world -> camera; a 3x3 matrix is read too),
//   `translation` (metres, world -> camera) and `fisheye`. anipose's variant (integer sizes,
//   trailing commas, [cam_0]) reads the same. Tables named metadata, capture_volume, charuco or
//   checkerboard are not cameras (as in Pose2Sim). Our floor is the table [metadata.floor]
//   (`normal`, `offset`: world frame), which the others skip with [metadata].
// * OpenCV YAML (cv::FileStorage; .yml, .yaml, also .xml, .json): `cameras`, a list with one entry
//   per camera (name, image_width, image_height, camera_matrix, distortion_coefficients, fisheye,
//   rotation (Rodrigues 3x1 or a 3x3 matrix), translation), and the floor as ground_normal,
//   ground_offset (world frame). The single-camera file of `mocap calibrate intrinsics` (those keys
//   at the top level, without `cameras`) reads as a one-camera rig named kDefaultCamera (or its
//   `camera_name`) whose frame is the world, its ground plane the floor.
//
// Readers refuse anything else (a missing, empty, truncated, oversized or binary file, a missing or
// malformed key, a camera_problem(), two cameras of one name) with a mocap::InputError naming the
// file and, where known, the line, the table or camera and the key. An all-zero distortion reads
// as none (empty).

#include <filesystem>
#include <string>
#include <string_view>

#include "camera/rig.hpp"

namespace mocap::camera {

enum class RigFormat { toml, yaml };

// By extension: .toml is TOML, .yml and .yaml OpenCV YAML; reading also takes OpenCV's .xml and
// .json, and any other name as TOML when its first line that is not blank or a comment starts
// with '[' (else OpenCV). Throws InputError naming the file for another extension.
RigFormat rig_format_for_writing(const std::filesystem::path& file);

Rig read_rig(const std::filesystem::path& file);
// Writes the rig (rig_problem() must be empty: std::invalid_argument otherwise). Throws InputError
// naming the file when it cannot be written. The file is written beside and renamed into place.
void write_rig(const std::filesystem::path& file, const Rig& rig);

// The same from and to text; `name` stands for the file in messages.
Rig parse_rig_toml(std::string_view text, const std::string& name);
std::string format_rig_toml(const Rig& rig);
Rig parse_rig_yaml(std::string_view text, const std::string& name);
std::string format_rig_yaml(const Rig& rig);

// A rig file's text, read whole; InputError naming the file when it is missing, empty, not a
// regular file or larger than a rig file can be (1 MiB).
std::string read_rig_text(const std::filesystem::path& file);

}  // namespace mocap::camera
