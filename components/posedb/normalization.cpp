#include "posedb/normalization.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mocap::posedb {
namespace {

struct Limb {
  Joint a, b;
  float length_m;  // canonical length (CMU train medians, ../shared/data/mocap/bandai/README.md)
};

// Limbs whose 2D length can only shrink under projection; the one that shrinks least sets the
// scale.
constexpr Limb kLimbs[] = {
    {Joint::right_shoulder, Joint::right_elbow, 0.289f},
    {Joint::left_shoulder, Joint::left_elbow, 0.289f},
    {Joint::right_elbow, Joint::right_wrist, 0.196f},
    {Joint::left_elbow, Joint::left_wrist, 0.196f},
    {Joint::right_hip, Joint::right_knee, 0.412f},
    {Joint::left_hip, Joint::left_knee, 0.412f},
    {Joint::right_knee, Joint::right_ankle, 0.423f},
    {Joint::left_knee, Joint::left_ankle, 0.423f},
    {Joint::root, Joint::neck, 0.419f},
};

bool present(const glm::vec2& p) { return std::isfinite(p.x) && std::isfinite(p.y); }

float bbox_height(std::span<const glm::vec2, kBodyJoints> points) {
  float lo = std::numeric_limits<float>::max(), hi = -lo;
  for (const auto& p : points) {
    if (!present(p)) continue;
    lo = std::min(lo, p.y);
    hi = std::max(hi, p.y);
  }
  return hi - lo;
}

float limb_scale(std::span<const glm::vec2, kBodyJoints> points) {
  float best = 0.0f;
  for (const Limb& l : kLimbs) {
    const glm::vec2 a = points[index(l.a)], b = points[index(l.b)];
    if (present(a) && present(b))
      best = std::max(best, std::hypot(a.x - b.x, a.y - b.y) / l.length_m);
  }
  return best;  // image units per metre
}

}  // namespace

std::string_view scaling_name(Scaling s) {
  return s == Scaling::bbox_height ? "bbox_height" : "bone_length";
}

bool parse_scaling(std::string_view text, Scaling& out) {
  if (text == "bbox_height" || text == "bbox") return out = Scaling::bbox_height, true;
  if (text == "bone_length" || text == "bones") return out = Scaling::bone_length, true;
  return false;
}

bool normalize_pose(std::span<const glm::vec2, kBodyJoints> points, Scaling scaling,
                    PoseVector& out) {
  const glm::vec2 root = points[index(Joint::root)];
  if (!present(root)) return false;
  int count = 0;
  for (const auto& p : points) count += present(p) ? 1 : 0;
  if (count < 3) return false;
  const float extent = scaling == Scaling::bbox_height ? bbox_height(points) : limb_scale(points);
  if (!(extent > 1e-6f) || !std::isfinite(extent)) return false;
  const float s = 1.0f / extent;
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  for (int j = 0; j < kBodyJoints - 1; ++j) {
    const glm::vec2 p = points[j];
    out[2 * j] = present(p) ? (p.x - root.x) * s : nan;
    out[2 * j + 1] = present(p) ? (p.y - root.y) * s : nan;
  }
  return true;
}

}  // namespace mocap::posedb
