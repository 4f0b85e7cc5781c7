#include "core/keypoint_layout.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace mocap {
namespace {

constexpr std::string_view kCoco17Names[] = {
    "nose",       "left_eye",       "right_eye",   "left_ear",   "right_ear",  "left_shoulder",
    "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist", "left_hip",
    "right_hip",  "left_knee",      "right_knee",  "left_ankle", "right_ankle"};

constexpr std::string_view kBody25Names[] = {
    "Nose",   "Neck",  "RShoulder", "RElbow",    "RWrist",    "LShoulder", "LElbow",
    "LWrist", "MidHip", "RHip",     "RKnee",     "RAnkle",    "LHip",      "LKnee",
    "LAnkle", "REye",  "LEye",      "REar",      "LEar",      "LBigToe",   "LSmallToe",
    "LHeel",  "RBigToe", "RSmallToe", "RHeel"};

// OpenPose's experimental BODY_25B (poseParameters.cpp): COCO-17 order, then neck, head top, feet.
constexpr std::string_view kBody25bNames[] = {
    "Nose",   "LEye",   "REye",   "LEar",    "REar",      "LShoulder", "RShoulder",
    "LElbow", "RElbow", "LWrist", "RWrist",  "LHip",      "RHip",      "LKnee",
    "RKnee",  "LAnkle", "RAnkle", "UpperNeck", "HeadTop", "LBigToe",   "LSmallToe",
    "LHeel",  "RBigToe", "RSmallToe", "RHeel"};

constexpr std::string_view kCoco18Names[] = {
    "Nose", "Neck",  "RShoulder", "RElbow", "RWrist", "LShoulder", "LElbow", "LWrist", "RHip",
    "RKnee", "RAnkle", "LHip",    "LKnee",  "LAnkle", "REye",      "LEye",   "REar",   "LEar"};

// VideoPose3D's HumanEva-I layout (ConvertHumanEva.m).
constexpr std::string_view kHumanEva15Names[] = {
    "pelvis",    "thorax",    "left_shoulder",  "left_elbow",  "left_wrist",
    "right_shoulder", "right_elbow", "right_wrist", "left_hip", "left_knee",
    "left_ankle", "right_hip", "right_knee",    "right_ankle", "head"};

constexpr JointSource one(int k, std::string_view how = "") { return {k, -1, false, how}; }
constexpr JointSource mid(int a, int b, bool either, std::string_view how) {
  return {a, b, either, how};
}

// Body15 order: head, neck, r_sho, r_elb, r_wri, l_sho, l_elb, l_wri, r_hip, r_kne, r_ank,
// l_hip, l_kne, l_ank, root.
constexpr std::array<JointSource, kBodyJoints> kCoco17Body = {
    mid(3, 4, true, "midpoint of the ears (one ear alone when the other is missing)"),
    mid(5, 6, false, "midpoint of the shoulders"),
    one(6), one(8), one(10), one(5), one(7), one(9), one(12), one(14), one(16), one(11), one(13),
    one(15), mid(11, 12, false, "midpoint of the hips")};

constexpr std::array<JointSource, kBodyJoints> kBody25Body = {
    mid(17, 18, true, "midpoint of the ears (one ear alone when the other is missing)"),
    one(1, "OpenPose Neck"),
    one(2), one(3), one(4), one(5), one(6), one(7), one(9), one(10), one(11), one(12), one(13),
    one(14), one(8, "OpenPose MidHip")};

constexpr std::array<JointSource, kBodyJoints> kBody25bBody = {
    one(18, "HeadTop"), one(17, "UpperNeck"),
    one(6), one(8), one(10), one(5), one(7), one(9), one(12), one(14), one(16), one(11), one(13),
    one(15), mid(11, 12, false, "midpoint of the hips (BODY_25B has no MidHip)")};

constexpr std::array<JointSource, kBodyJoints> kCoco18Body = {
    mid(16, 17, true, "midpoint of the ears (one ear alone when the other is missing)"),
    one(1, "OpenPose Neck"),
    one(2), one(3), one(4), one(5), one(6), one(7), one(8), one(9), one(10), one(11), one(12),
    one(13), mid(8, 11, false, "midpoint of the hips")};

constexpr std::array<JointSource, kBodyJoints> kHumanEva15Body = {
    one(14, "headDistal"), one(1, "thorax = mean(torsoProximal, headProximal)"),
    one(5), one(6), one(7), one(2), one(3), one(4), one(11), one(12), one(13), one(8), one(9),
    one(10), one(0, "pelvis (torsoDistal)")};

const std::array<KeypointLayout, 5> kLayouts = {{
    {LayoutId::coco17, "COCO-17", kCoco17Names, kCoco17Body},
    {LayoutId::body25, "BODY_25", kBody25Names, kBody25Body},
    {LayoutId::body25b, "BODY_25B", kBody25bNames, kBody25bBody},
    {LayoutId::coco18, "COCO-18", kCoco18Names, kCoco18Body},
    {LayoutId::humaneva15, "HumanEva-15", kHumanEva15Names, kHumanEva15Body},
}};

std::string fold(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      out.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
    }
  }
  return out;
}

bool present(std::span<const float> xyc, int k) {
  const float x = xyc[3 * k], y = xyc[3 * k + 1], c = xyc[3 * k + 2];
  return c > 0.0f && std::isfinite(x) && std::isfinite(y);
}

}  // namespace

const KeypointLayout& layout(LayoutId id) { return kLayouts[static_cast<int>(id)]; }

std::span<const KeypointLayout> all_layouts() { return kLayouts; }

const KeypointLayout* find_layout(std::string_view layout_name) {
  const std::string wanted = fold(layout_name);
  for (const auto& l : kLayouts) {
    if (fold(l.name) == wanted) return &l;
  }
  return nullptr;
}

void to_body15(const KeypointLayout& lay, std::span<const float> xyc, std::span<float> body) {
  if (xyc.size() < lay.keypoints.size() * 3 || body.size() < kBodyJoints * 3) {
    throw std::invalid_argument("to_body15: " + std::string(lay.name) + " needs " +
                                std::to_string(lay.keypoints.size() * 3) + " values, got " +
                                std::to_string(xyc.size()));
  }
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  for (int j = 0; j < kBodyJoints; ++j) {
    const JointSource& s = lay.body[j];
    float* out = &body[3 * j];
    const bool has_a = present(xyc, s.first);
    const bool has_b = s.second >= 0 && present(xyc, s.second);
    if (s.second < 0 || (has_a != has_b && s.either_alone)) {
      const int k = has_a ? s.first : s.second;
      if (!has_a && !has_b) {
        out[0] = out[1] = nan;
        out[2] = 0.0f;
        continue;
      }
      out[0] = xyc[3 * k];
      out[1] = xyc[3 * k + 1];
      out[2] = xyc[3 * k + 2];
    } else if (has_a && has_b) {
      out[0] = 0.5f * (xyc[3 * s.first] + xyc[3 * s.second]);
      out[1] = 0.5f * (xyc[3 * s.first + 1] + xyc[3 * s.second + 1]);
      out[2] = std::min(xyc[3 * s.first + 2], xyc[3 * s.second + 2]);
    } else {
      out[0] = out[1] = nan;
      out[2] = 0.0f;
    }
  }
}

}  // namespace mocap
