#pragma once
// OpenPose `--write_json` output: one `*_keypoints.json` file per frame, many people per file.
//
// A file is {"version": 1.3, "people": [{"person_id": [-1], "pose_keypoints_2d": [x, y, c, ...],
// "face_keypoints_2d": [], "hand_*_keypoints_2d": [], "*_keypoints_3d": []}, ...]}. Only
// `pose_keypoints_2d` and `person_id` are read; the face, hand and 3D arrays are ignored.
//
// The layout follows from the keypoint count: 18 → COCO-18, 17 → COCO-17, 25 → BODY_25 or
// BODY_25B. Those two cannot be told apart by count, so the caller says which one, or asks for
// the geometric test of detect_body25_variant().
//
// OpenPose writes an undetected keypoint as (0, 0, 0); the reader turns every keypoint with
// confidence <= 0 into (NaN, NaN, 0), so that nobody mistakes (0, 0) for a pixel.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/keypoint_layout.hpp"
#include "core/messages.hpp"

namespace mocap::io {

// What 25 keypoints mean.
enum class Body25Choice { body25, body25b, detect };

struct OpenPoseOptions {
  Body25Choice body25 = Body25Choice::body25;
  // Larger files are refused before they are read (OpenPose writes ~1 KB per person).
  std::uintmax_t max_file_bytes = 64u << 20;
  // A folder whose frame numbers span more is refused (one empty frame is kept per number):
  // a million frames is 9 hours at 30 fps.
  std::int64_t max_frames = 1'000'000;
};

// Parses the text of one keypoints file. Throws InputError naming `source` and, for bad values,
// the JSON path (e.g. "people[3].pose_keypoints_2d[17]"). `header.frame` is left at 0.
People2D parse_openpose_json(std::string_view text, const std::string& source,
                             const OpenPoseOptions& options = {});

// Reads one keypoints file; throws InputError (file cannot be read, not JSON, bad shape or values).
People2D read_openpose_file(const std::filesystem::path& file, const OpenPoseOptions& options = {});

// Evidence for BODY_25 against BODY_25B in 25-keypoint people. Index 15 is an eye (next to the
// nose) in BODY_25 but an ankle (far from it) in BODY_25B. For each person with a nose and
// index 15 or 16, r = (distance from the nose to the nearer of 15/16) / (largest distance from
// the nose to any detected keypoint): r > 0.6 votes BODY_25B; r < 0.25 votes BODY_25 when at
// least 8 keypoints are detected (a lone head has r near 0.5 and must not vote); otherwise the
// person abstains. On the shared data r stays below 0.27 for BODY_25 and above 0.69 for BODY_25B.
struct Body25Votes {
  int body25 = 0;
  int body25b = 0;
  int abstained = 0;
  void add(const Body25Votes& other);
  // BODY_25B only when it has a strict majority; BODY_25 (OpenPose's default) otherwise.
  LayoutId decision() const { return body25b > body25 ? LayoutId::body25b : LayoutId::body25; }
};

// Counts the votes of people given as 25 keypoints (x, y, c) each, in either layout's order.
Body25Votes vote_body25_variant(const People2D& frame);

// One frame file of a folder and the frame number in its name.
struct FrameFile {
  std::filesystem::path path;
  std::int64_t number = 0;
};

// The frame number of a file name: the last run of digits in the name without its extension
// ("video_000000000123_keypoints.json" → 123, "cam01.0042.json" → 42). nullopt if none.
std::optional<std::int64_t> frame_number(std::string_view file_name);

// Every `*.json` file of `folder` that has a frame number, in frame order (then by name).
// Throws InputError if the folder cannot be listed.
std::vector<FrameFile> list_frame_files(const std::filesystem::path& folder);

enum class FrameProblemKind { missing, malformed, duplicate, layout_mismatch };

struct FrameProblem {
  FrameProblemKind kind;
  std::int64_t frame = 0;  // the first frame concerned
  std::int64_t count = 1;  // frames concerned: a run of missing numbers is one problem
  std::string file;        // empty for missing frames
  std::string message;     // one line, ready to print
};

struct OpenPoseSequence {
  LayoutId layout = LayoutId::body25;
  Body25Votes votes;                   // when 25 keypoints were detected with Body25Choice::detect
  std::int64_t first_frame = 0;        // frame number of frames[0]
  std::vector<People2D> frames;        // one per number first_frame..last, gaps as empty frames
  std::vector<FrameProblem> problems;  // in frame order
};

// Reads a folder of keypoints files. Never throws for a bad or missing frame: such a frame stays
// empty (no people) and gets a FrameProblem (a run of missing frames gets one). Every frame takes
// the layout of the majority of the files; a file with another keypoint count is a problem.
// header.frame is the frame number, header.seq the index in `frames`, header.stream the folder.
// Throws InputError only when the folder cannot be listed, holds no numbered *.json file or its
// numbers span > max_frames.
OpenPoseSequence read_openpose_folder(const std::filesystem::path& folder,
                                      const OpenPoseOptions& options = {});

std::string_view to_string(FrameProblemKind kind);

// The writer: one frame as OpenPose writes it (version 1.3, per person `person_id` [id] and
// `pose_keypoints_2d` in the frame's layout; a keypoint without confidence or coordinates as
// 0, 0, 0), which read_openpose_file reads back to the same people (25-keypoint layouts: given
// the same Body25Choice).
std::string openpose_json_text(const People2D& frame);

// The file of frame `number` in `folder`, as OpenPose names it:
// `<stem>_<number, 12 digits>_keypoints.json`.
std::filesystem::path openpose_file_name(const std::filesystem::path& folder,
                                         const std::string& stem, std::int64_t number);

// Writes `frame` to `file` whole (a temporary file renamed into place: a file is complete or
// absent). Throws std::runtime_error naming the file when it cannot be written.
void write_openpose_file(const std::filesystem::path& file, const People2D& frame);

}  // namespace mocap::io
