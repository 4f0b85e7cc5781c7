#pragma once
// What the multi-view library is given per frame: for every view, the people detected in it as
// keypoints (x, y, confidence) in *undistorted* pixels, all in one keypoint set. The set is any
// 2D layout (the 15 body joints, or a detector's own keypoints such as BODY_25B with its feet and
// head top): association, triangulation and tracking work on every keypoint of the set, and the
// 15 body joints are derived from the triangulated keypoints afterwards, so a layout's own
// keypoints (Pose2Sim's TRC markers are BODY_25B keypoints) stay available in 3D.

#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include "core/body15.hpp"
#include "core/keypoint_layout.hpp"

namespace mocap::multiview {

// Whether a keypoint (x, y, confidence) is there: a finite confidence above `min_confidence`
// and finite coordinates within a million pixels (anything farther is garbage, not a pixel).
inline bool usable_keypoint(float x, float y, float confidence, float min_confidence = 0.0f) {
  constexpr float kFar = 1e6f;
  return confidence > min_confidence && confidence < std::numeric_limits<float>::infinity() &&
         std::abs(x) < kFar && std::abs(y) < kFar;
}

// The keypoints of the input and how the 15 body joints are made from them.
struct KeypointSet {
  int count = kBodyJoints;
  std::array<JointSource, kBodyJoints> body{};
  std::string_view name;

  // The 15 body joints themselves (core/body15.hpp order).
  static KeypointSet body15();
  // A detector layout's keypoints (core/keypoint_layout.hpp), its body joints as the layout maps
  // them.
  static KeypointSet of(const KeypointLayout& layout);
};

// One frame's detections, view by view. Reused from frame to frame: reset() keeps the memory.
class FrameObservations {
 public:
  FrameObservations() = default;
  FrameObservations(int views, int keypoints) { reset(views, keypoints); }

  // Empties every view; `views` views of people with `keypoints` keypoints each.
  void reset(int views, int keypoints);

  // A new person in `view`: its keypoints as keypoints() × (x, y, confidence), all missing
  // (NaN, NaN, 0) until filled in. A keypoint with confidence <= 0 or a non-finite coordinate is
  // missing. The span stays valid until the next add_person() or reset().
  std::span<float> add_person(int view);
  // The same, copying `xyc` (keypoints() × 3 values).
  void add_person(int view, std::span<const float> xyc);

  int views() const { return static_cast<int>(views_.size()); }
  int keypoints() const { return keypoints_; }
  int people(int view) const;
  std::span<const float> person(int view, int index) const;

 private:
  int keypoints_ = 0;
  std::vector<std::vector<float>> views_;
};

}  // namespace mocap::multiview
