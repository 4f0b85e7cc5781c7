#pragma once
// 2D/3D keypoint layouts the project reads (detectors, OpenPose, HumanEva) and how each one is
// mapped onto the internal 15-joint body.

#include <array>
#include <span>
#include <string_view>
#include <vector>

#include "core/body15.hpp"

namespace mocap {

enum class LayoutId { coco17, body25, body25b, coco18, humaneva15 };

// How one Body15 joint is made from a layout's keypoints: one keypoint, or the midpoint of two.
struct JointSource {
  int first = -1;
  int second = -1;           // -1: the joint is `first` itself
  bool either_alone = false; // midpoint joints: use the one that is present when the other is missing
  std::string_view how;      // one line for documentation and `--help` output
};

struct KeypointLayout {
  LayoutId id;
  std::string_view name;
  std::span<const std::string_view> keypoints;
  std::array<JointSource, kBodyJoints> body;
};

const KeypointLayout& layout(LayoutId id);
std::span<const KeypointLayout> all_layouts();
// Accepts the canonical name ("COCO-17", "BODY_25", ...) case-insensitively, with or without
// separators ("coco17", "body25b"). Returns nullptr when unknown.
const KeypointLayout* find_layout(std::string_view name);

// Converts keypoints of `layout` (x, y, confidence; stride 3) to the 15 body joints (x, y,
// confidence). A keypoint with confidence <= 0 or a NaN coordinate is missing; a body joint made
// from missing keypoints gets NaN coordinates and confidence 0.
void to_body15(const KeypointLayout& layout, std::span<const float> keypoints_xyc,
               std::span<float> body_xyc);

}  // namespace mocap
