#pragma once
// Where a keypoint layout puts its joints relative to the canonical body's joint centres
// (docs/keypoint-layouts.md), and the correction that moves a layout's keypoints onto them.
//
// The model, per Body15 joint, is an offset made of vectors the 2D keypoints themselves give, so
// it applies in the image without knowing depth:
//   basis "shoulders": offset = along * T + lateral * (left_shoulder - right_shoulder)
//   basis "hips":      offset = along * T + lateral * (left_hip - right_hip)
//   basis "bone":      offset = along * (joint - parent joint)            (limb joints)
//   basis "none":      no offset
// (and, in 3D only, + forward * N for the shoulders and hips bases, N the trunk's normal)
// with T = midpoint(shoulders) - midpoint(hips), the trunk, all from the layout's own keypoints.
// Under (near-)orthographic projection of a rigid trunk this is exact for offsets in the plane of
// the trunk (and along the bone for limbs); an offset out of that plane (towards the front or
// back of the body) cannot be made from 2D vectors: it is fitted and stored (`forward`) but used
// only in 3D (apply_layout_offsets_3d).
//
// Stored as data, one file per layout in calibration/layouts/ (a small YAML subset, see
// load_layout_offsets), written by `mocap calibrate layout`.

#include <array>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/body15.hpp"
#include "core/keypoint_layout.hpp"

namespace mocap::recon {

enum class OffsetBasis { none, shoulders, hips, bone };

std::string_view basis_name(OffsetBasis b);

struct JointOffset {
  OffsetBasis basis = OffsetBasis::none;
  float along = 0.0f;    // times T (shoulders, hips) or times the parent bone (bone)
  float lateral = 0.0f;  // times the girdle's left-minus-right vector (shoulders, hips)
  // Times N = (lateral vector x T) / |lateral vector|, the trunk's normal (towards the front,
  // about |T| long): 3D only. It cannot be formed from 2D keypoints, so the 2D correction leaves
  // it out; it is kept to map canonical 3D joints back into the layout's definition.
  float forward = 0.0f;
};

struct LayoutOffsets {
  LayoutId layout = LayoutId::body25b;
  std::string source;  // the file it was read from (for messages and reports)
  std::array<JointOffset, kBodyJoints> joints{};
};

inline constexpr std::string_view kLayoutOffsetsFormat = "mocap-layout-offsets/1";

// Reads and validates a layout file; throws InputError naming the file and line on anything
// unexpected (unknown key, missing or repeated joint, bad number, a coefficient beyond ±2,
// truncation, binary garbage).
LayoutOffsets load_layout_offsets(const std::filesystem::path& file);
LayoutOffsets parse_layout_offsets(std::string_view text, const std::string& file_name);
// The text load_layout_offsets reads back; `header` lines are written as comments first.
std::string format_layout_offsets(const LayoutOffsets& offsets, std::string_view header);

// "body25b.yaml" for BODY_25B: the file name of a layout in calibration/layouts/.
std::string layout_offsets_file_name(LayoutId layout);
// Where `auto` looks, first hit wins: $MOCAP_LAYOUT_DIR, <install root>/calibration/layouts
// (the executable lives in <root>/<build>/bin), ./calibration/layouts.
std::optional<std::filesystem::path> find_layout_offsets(LayoutId layout);

// What a `layout_offsets` setting (graph parameter, command-line option) means: "off" -> none;
// "auto" -> the file of `layout` if one exists (none otherwise); anything else -> that file,
// which must be for `layout`. Throws InputError for a file that cannot be used.
std::optional<LayoutOffsets> resolve_layout_offsets(std::string_view setting, LayoutId layout);

// Moves the layout's Body15 joints (x, y, confidence; image pixels) onto the canonical joints in
// place. All offsets are computed from the uncorrected joints. A joint whose basis needs a
// missing joint is left as it is.
void apply_layout_offsets(const LayoutOffsets& offsets, std::span<float, kBodyJoints * 3> body_xyc);

// The same in 3D. direction +1: layout keypoints -> canonical joints; -1: canonical joints -> where
// the layout would put its keypoints (the inverse, its vectors taken from the canonical joints;
// used to score a canonical reconstruction against truth in the layout's own definition).
void apply_layout_offsets_3d(const LayoutOffsets& offsets,
                             std::array<glm::vec3, kBodyJoints>& joints, float direction = 1.0f);

}  // namespace mocap::recon
