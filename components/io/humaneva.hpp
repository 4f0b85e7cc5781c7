#pragma once
// HumanEva-I as VideoPose3D prepares it (../shared/data/eval/humaneva_i_videopose3d/, see its
// README): 3D joint positions and their ground-truth 2D projections in three colour cameras,
// 15 joints in the HumanEva-15 order of core/keypoint_layout.hpp, 60 Hz.
//
// data_3d_humaneva15.npz holds `positions_3d`, a pickled dict {"Train/S1": {"Walking 1 chunk0":
// float32 (frames, 15, 3), ...}, ...}; data_2d_humaneva15_gt.npz holds `positions_2d` (the same
// keys, each a list of three (frames, 15, 2) arrays for C1, C2, C3) and `metadata`. VideoPose3D
// cut every sequence into chunks where the mocap was invalid and kept only the valid chunks, so
// chunk numbers have gaps. humaneva_cameras.json holds the camera poses (VideoPose3D) and
// approximate pinhole intrinsics (fitted for that folder).

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "camera/rig.hpp"
#include "core/body15.hpp"
#include "io/npz.hpp"

namespace mocap::io::humaneva {

inline constexpr int kJoints = 15;
inline constexpr int kCameras = 3;
inline constexpr double kFps = 60.0;
inline constexpr std::array<std::string_view, kCameras> kCameraNames = {"C1", "C2", "C3"};
inline constexpr std::string_view kPositions3dFile = "data_3d_humaneva15.npz";
inline constexpr std::string_view kPositions2dFile = "data_2d_humaneva15_gt.npz";
inline constexpr std::string_view kCamerasFile = "humaneva_cameras.json";

// HumanEva-I's own partitions of trial 1 of each action (its "Test" part has no public mocap).
enum class Split { train, validate };
std::string_view to_string(Split split);

using Pose3 = std::array<glm::vec3, kJoints>;  // metres, HumanEva world frame (Z up)
using Pose2 = std::array<glm::vec2, kJoints>;  // pixels of a 640×480 image, x right, y down

// HumanEva-I frame numbers [begin, end).
struct FrameRange {
  int begin = 0;
  int end = 0;
  int size() const { return end - begin; }
};

// The frames of (subject, action) trial 1 that a split covers, as VideoPose3D's
// prepare_data_humaneva.py fixes them, e.g. (train, "S1", "Walking") → [590, 1203).
std::optional<FrameRange> frame_range(Split split, std::string_view subject,
                                      std::string_view action);

struct Chunk {
  Split split = Split::train;
  std::string subject;  // "S1", "S2", "S3"
  std::string action;   // "Walking", "Jog", "Box", "Gestures", "ThrowCatch"
  int trial = 1;
  int chunk = 0;
  std::string key;   // as in the files: "Walking 1 chunk0"
  FrameRange range;  // of the whole (split, subject, action); the chunks lie inside it
  // HumanEva frame of positions_3d[0]. Known for chunk 0 only: the invalid chunks before a later
  // chunk were dropped without their lengths.
  std::optional<int> first_frame;
  std::vector<Pose3> positions_3d;
  std::array<std::vector<Pose2>, kCameras> positions_2d;  // C1..C3; empty if 2D was not loaded

  std::size_t frames() const { return positions_3d.size(); }
};

struct Dataset {
  std::vector<Chunk> chunks;  // by split, subject, action, chunk number

  // Chunks matching every given filter (empty strings match everything).
  std::vector<const Chunk*> select(std::optional<Split> split, std::string_view subject = "",
                                   std::string_view action = "") const;
};

struct LoadOptions {
  bool load_2d = true;
  NpyLimits limits;
};

// Reads the 3D file and, with load_2d, the 2D file of `folder`, and checks that both hold the
// same chunks with the same frame counts. Throws InputError.
Dataset load_dataset(const std::filesystem::path& folder, const LoadOptions& options = {});
Dataset read_positions_3d(const std::filesystem::path& npz, const NpyLimits& limits = {});
void attach_positions_2d(Dataset& dataset, const std::filesystem::path& npz,
                         const NpyLimits& limits = {});
// The same from an archive already open (e.g. NpzFile::from_bytes); `source` names it in messages.
Dataset read_positions_3d(const NpzFile& file, const std::string& source);
void attach_positions_2d(Dataset& dataset, const NpzFile& file, const std::string& source);

// Subject ("S1".."S3") → the rig of that subject's session: the three cameras C1..C3 (640x480,
// the approximate pinhole intrinsics fitted without distortion, see the README; VideoPose3D's
// orientation and centre as the pose) in HumanEva's world (metres, Z up), the floor its Z = 0
// plane. Throws InputError naming the JSON key.
std::map<std::string, camera::Rig> load_cameras(const std::filesystem::path& json);
// The same from the file's text; `source` names it in messages.
std::map<std::string, camera::Rig> parse_cameras(std::string_view text, const std::string& source);

// HumanEva-15 → Body15 with the HumanEva-15 layout of core/keypoint_layout.hpp. Every Body15
// joint is one HumanEva joint: root = pelvis (torsoDistal), neck = thorax, head = headDistal.
std::array<glm::vec3, kBodyJoints> to_body15(const Pose3& pose);

}  // namespace mocap::io::humaneva
