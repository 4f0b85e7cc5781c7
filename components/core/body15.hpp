#pragma once
// The project's internal 15-joint body. Every output of the project names its joints with these
// names, in this order; every input layout and mocap family is mapped onto them.

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace mocap {

enum class Joint : std::uint8_t {
  head,
  neck,
  right_shoulder,
  right_elbow,
  right_wrist,
  left_shoulder,
  left_elbow,
  left_wrist,
  right_hip,
  right_knee,
  right_ankle,
  left_hip,
  left_knee,
  left_ankle,
  root,  // mid-hips
};

inline constexpr int kBodyJoints = 15;

inline constexpr std::array<std::string_view, kBodyJoints> kJointNames = {
    "head",      "neck",       "right_shoulder", "right_elbow", "right_wrist",
    "left_shoulder", "left_elbow", "left_wrist", "right_hip",  "right_knee",
    "right_ankle", "left_hip",  "left_knee",     "left_ankle", "root"};

// The tree the 15 joints form, rooted at `root`; used for bone lengths and drawing.
// kJointParent[j] is the parent of joint j, or -1 for the root.
inline constexpr std::array<int, kBodyJoints> kJointParent = {
    1,   // head <- neck
    14,  // neck <- root
    1,   // right_shoulder <- neck
    2,   // right_elbow <- right_shoulder
    3,   // right_wrist <- right_elbow
    1,   // left_shoulder <- neck
    5,   // left_elbow
    6,   // left_wrist
    14,  // right_hip <- root
    8,   // right_knee
    9,   // right_ankle
    14,  // left_hip <- root
    11,  // left_knee
    12,  // left_ankle
    -1,  // root
};

// Left/right mirror of each joint (used for symmetric augmentation and evaluation).
inline constexpr std::array<int, kBodyJoints> kJointMirror = {0, 1, 5, 6, 7, 2, 3, 4,
                                                              11, 12, 13, 8, 9, 10, 14};

constexpr int index(Joint j) { return static_cast<int>(j); }
constexpr std::string_view name(Joint j) { return kJointNames[static_cast<int>(j)]; }

std::optional<Joint> joint_from_name(std::string_view name);

}  // namespace mocap
