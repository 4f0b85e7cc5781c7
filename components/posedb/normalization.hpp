#pragma once
// The method's 2D pose normalisation: root-centred, then scaled. Applied identically to the
// database projections and to every detected pose, so that they can be compared directly.

#include <array>
#include <span>
#include <string_view>

#include <glm/vec2.hpp>

#include "core/body15.hpp"

namespace mocap::posedb {

// A normalised pose: the 14 non-root joints (Body15 order, root last and left out) as x, y.
inline constexpr int kPoseDims = 2 * (kBodyJoints - 1);
using PoseVector = std::array<float, kPoseDims>;

enum class Scaling {
  bbox_height,  // the paper: the 2D bounding box of the joints gets height 1
  bone_length,  // the paper's alternative: the least foreshortened limb gets its canonical length
};

std::string_view scaling_name(Scaling s);
bool parse_scaling(std::string_view text, Scaling& out);

// Normalises 15 image points (x right, y down; NaN = missing). Missing joints come out as NaN.
// Returns false when the pose cannot be normalised (root missing, or fewer than 3 joints, or a
// degenerate extent); `out` is then unspecified.
bool normalize_pose(std::span<const glm::vec2, kBodyJoints> points, Scaling scaling,
                    PoseVector& out);

}  // namespace mocap::posedb
