#pragma once
// A frame's detections as rays in the world, and the geometric costs of the association: how far
// apart two detections' rays pass (are they one person seen by two views?) and how far a
// detection's rays pass from a 3D person (is it this person, seen by one more view?). Costs are
// in metres, so one threshold fits every camera distance and focal length.
//
// A cost is a confidence-weighted trimmed mean over the keypoints both sides have: the distances,
// capped at `cap_m`, are sorted and the smallest ones making up a share of the weight averaged.
// A wrong keypoint (a left/right swap, a jump) or a badly predicted limb does not count, while a
// detection of somebody else is far at every keypoint. Two detections are compared on most of
// their keypoints (`keep_pair`: a chance agreement of two false detections must not pass on a
// few), a detection and a prediction on the better part (`keep_point`: swinging limbs are
// predicted worst).

#include <span>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "multiview/observations.hpp"
#include "multiview/view_geometry.hpp"

namespace mocap::multiview {

struct RayCostOptions {
  // Keypoints at or below this confidence are left out of the association.
  float min_confidence = 0.0f;
  // A detection with fewer usable keypoints is not associated (its count is reported).
  int min_keypoints = 4;
  // Keypoints two sides must share for a cost; fewer: no cost (the pair is not compared).
  int min_common = 3;
  // Per-keypoint distances are capped here (metres).
  float cap_m = 0.5f;
  // Share of the keypoints' weight averaged, smallest distances first.
  float keep_pair = 0.8f;
  float keep_point = 0.6f;
};

struct Detection {
  int view = 0;
  int index = 0;      // in the view's people
  int keypoints = 0;  // usable ones
};

class DetectionTable {
 public:
  // Every detection of `frame` with at least options.min_keypoints usable keypoints; the others
  // are counted in sparse().
  void build(const FrameObservations& frame, std::span<const ViewGeometry> views,
             const RayCostOptions& options);

  int size() const { return static_cast<int>(detections_.size()); }
  int keypoints() const { return keypoints_; }
  const Detection& operator[](int i) const { return detections_[static_cast<std::size_t>(i)]; }
  int sparse() const { return sparse_; }
  // Confidence of keypoint k of detection i (0: not usable).
  float confidence(int i, int k) const { return confidence_[index(i, k)]; }
  const glm::vec3& ray(int i, int k) const { return rays_[index(i, k)]; }
  const glm::vec3& centre(int view) const { return centres_[static_cast<std::size_t>(view)]; }

  // Ray-to-ray cost of two detections in different views; NaN with fewer than min_common
  // shared keypoints. Rays whose closest points lie behind either camera count as cap_m.
  float pair_cost(int a, int b, const RayCostOptions& options) const;
  // Cost of detection i against 3D keypoints (world, NaN where unknown): the distance from each
  // point to the ray of the same keypoint; NaN with fewer than min_common comparable keypoints.
  float point_cost(int i, std::span<const glm::vec3> points, const RayCostOptions& options) const;

 private:
  float trimmed_mean(int count, int min_common, float keep) const;
  std::size_t index(int i, int k) const {
    return static_cast<std::size_t>(i) * static_cast<std::size_t>(keypoints_) +
           static_cast<std::size_t>(k);
  }

  int keypoints_ = 0;
  int sparse_ = 0;
  std::vector<Detection> detections_;
  std::vector<glm::vec3> rays_;
  std::vector<float> confidence_;
  std::vector<glm::vec3> centres_;
  // Scratch of the costs: (distance, weight) per keypoint. Costs are computed by one thread.
  mutable std::vector<std::pair<float, float>> terms_;
};

}  // namespace mocap::multiview
