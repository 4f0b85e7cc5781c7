#include "motion/canonical_body.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <glm/geometric.hpp>

namespace mocap::motion {
namespace {

constexpr int kRoot = index(Joint::root);
constexpr int kNeck = index(Joint::neck);
constexpr int kRightShoulder = index(Joint::right_shoulder);
constexpr int kLeftShoulder = index(Joint::left_shoulder);
constexpr int kRightHip = index(Joint::right_hip);
constexpr int kLeftHip = index(Joint::left_hip);

bool finite(const glm::vec3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

float median(std::vector<float>& v) {
  if (v.empty()) return 0.0f;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2 == 1) return *mid;
  const float upper = *mid;
  return 0.5f * (upper + *std::max_element(v.begin(), mid));
}

// Angle between the trunk (root -> neck) and neck -> shoulder `s`.
float shoulder_angle(const Body15& b, int s) {
  const glm::vec3 trunk = b[kNeck] - b[kRoot], arm = b[s] - b[kNeck];
  const float lt = glm::length(trunk), la = glm::length(arm);
  if (!(lt > 1e-6f) || !(la > 1e-6f)) return std::nanf("");
  return std::acos(std::clamp(glm::dot(trunk, arm) / (lt * la), -1.0f, 1.0f));
}

// The canonical numbers (metres, radians): medians of the cmu31 train split at 24 fps,
// recomputed by CanonicalBody.ConstantsAgreeWithCmuTrain.
BodyProportions make_canonical() {
  BodyProportions p;
  auto set = [&](Joint j, float metres) { p.bone_m[index(j)] = metres; };
  for (Joint side : {Joint::right_shoulder, Joint::left_shoulder}) set(side, 0.1854f);
  for (Joint side : {Joint::right_elbow, Joint::left_elbow}) set(side, 0.2886f);
  for (Joint side : {Joint::right_wrist, Joint::left_wrist}) set(side, 0.1955f);
  for (Joint side : {Joint::right_hip, Joint::left_hip}) set(side, 0.0753f);
  for (Joint side : {Joint::right_knee, Joint::left_knee}) set(side, 0.4118f);
  for (Joint side : {Joint::right_ankle, Joint::left_ankle}) set(side, 0.4233f);
  set(Joint::head, 0.1989f);
  set(Joint::neck, 0.4191f);
  p.shoulder_angle_rad = 1.7001f;  // 97.4 degrees
  return p;
}

}  // namespace

float joint_span_m(const BodyProportions& p) {
  const auto bone = [&](Joint j) { return p.bone_m[index(j)]; };
  return bone(Joint::head) + bone(Joint::neck) +
         0.5f * (bone(Joint::right_knee) + bone(Joint::left_knee)) +
         0.5f * (bone(Joint::right_ankle) + bone(Joint::left_ankle));
}

float canonical_stature_m() {
  return kStatureOverJointSpan * joint_span_m(canonical_proportions());
}

float BodyProportions::shoulder_width_m() const {
  return bone_m[kRightShoulder] * std::sin(shoulder_angle_rad) +
         bone_m[kLeftShoulder] * std::sin(shoulder_angle_rad);
}

float BodyProportions::total_bone_m() const {
  float sum = 0.0f;
  for (float b : bone_m) sum += b;
  return sum;
}

const BodyProportions& canonical_proportions() {
  static const BodyProportions canonical = make_canonical();
  return canonical;
}

BodyProportions proportions_of(const Body15& body) {
  BodyProportions p;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (kJointParent[j] >= 0) p.bone_m[j] = glm::length(body[j] - body[kJointParent[j]]);
  }
  p.shoulder_angle_rad =
      0.5f * (shoulder_angle(body, kRightShoulder) + shoulder_angle(body, kLeftShoulder));
  return p;
}

BodyProportions measure_proportions(std::span<const Body15> frames, bool symmetric) {
  std::array<std::vector<float>, kBodyJoints> lengths;
  std::vector<float> angles;
  for (const Body15& b : frames) {
    if (!std::all_of(b.begin(), b.end(), finite)) continue;
    const BodyProportions one = proportions_of(b);
    for (int j = 0; j < kBodyJoints; ++j) {
      if (kJointParent[j] >= 0) lengths[j].push_back(one.bone_m[j]);
    }
    for (int s : {kRightShoulder, kLeftShoulder}) {
      if (const float a = shoulder_angle(b, s); std::isfinite(a)) angles.push_back(a);
    }
  }
  BodyProportions p;
  for (int j = 0; j < kBodyJoints; ++j) p.bone_m[j] = median(lengths[j]);
  if (symmetric) {
    // The mean of the two sides' medians (a pooled median would pick one side's length when the
    // sides differ, as CMU's left and right upper arms do by 15 mm).
    const auto sided = p.bone_m;
    for (int j = 0; j < kBodyJoints; ++j) p.bone_m[j] = 0.5f * (sided[j] + sided[kJointMirror[j]]);
  }
  p.shoulder_angle_rad = median(angles);
  return p;
}

Body15 retarget(const Body15& body, const BodyProportions& p) {
  Body15 out;
  out[kRoot] = body[kRoot];
  // Hips: symmetric about the root along the source's hip line.
  const glm::vec3 across = body[kLeftHip] - body[kRightHip];
  const float across_length = glm::length(across);
  // Joints in kJointParent order are not sorted parent-first; walk the chains explicitly.
  auto bone = [&](int j) {
    const int parent = kJointParent[j];
    const glm::vec3 d = body[j] - body[parent];
    const float l = glm::length(d);
    out[j] = l > 1e-9f ? out[parent] + d * (p.bone_m[j] / l) : out[parent] + d;
  };
  bone(kNeck);
  bone(index(Joint::head));
  if (across_length > 1e-9f) {
    const glm::vec3 u = across / across_length;
    out[kRightHip] = out[kRoot] - u * p.bone_m[kRightHip];
    out[kLeftHip] = out[kRoot] + u * p.bone_m[kLeftHip];
  } else {
    bone(kRightHip);
    bone(kLeftHip);
  }
  // Shoulders: re-hung from the neck at the proportions' angle to the trunk, in the plane of the
  // trunk and the source shoulder.
  const glm::vec3 trunk = body[kNeck] - body[kRoot];
  const float trunk_length = glm::length(trunk);
  for (int s : {kRightShoulder, kLeftShoulder}) {
    const glm::vec3 d = body[s] - body[kNeck];
    if (trunk_length > 1e-9f) {
      const glm::vec3 t = trunk / trunk_length;
      const glm::vec3 side = d - glm::dot(d, t) * t;
      const float side_length = glm::length(side);
      if (side_length > 1e-6f * std::max(1.0f, glm::length(d))) {
        const glm::vec3 dir = std::cos(p.shoulder_angle_rad) * t +
                              std::sin(p.shoulder_angle_rad) * (side / side_length);
        out[s] = out[kNeck] + dir * p.bone_m[s];
        continue;
      }
    }
    bone(s);
  }
  for (Joint j : {Joint::right_elbow, Joint::right_wrist, Joint::left_elbow, Joint::left_wrist,
                  Joint::right_knee, Joint::right_ankle, Joint::left_knee, Joint::left_ankle})
    bone(index(j));
  return out;
}

std::string describe(const BodyProportions& p) {
  auto mm = [&](Joint j) { return static_cast<int>(std::lround(1000.0f * p.bone_m[index(j)])); };
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "bones (mm): head %d, trunk %d, neck-shoulder %d at %.1f deg, upper arm %d, "
                "forearm %d, hip half-width %d, thigh %d, shin %d",
                mm(Joint::head), mm(Joint::neck), mm(Joint::right_shoulder),
                static_cast<double>(p.shoulder_angle_rad * 180.0f / 3.14159265f),
                mm(Joint::right_elbow), mm(Joint::right_wrist), mm(Joint::right_hip),
                mm(Joint::right_knee), mm(Joint::right_ankle));
  return buf;
}

}  // namespace mocap::motion
