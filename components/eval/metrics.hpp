#pragma once
// 3D pose error metrics as ../shared/docs/EVALUATION.md defines them. Positions in metres,
// errors in millimetres (accelerations in mm/frame²).
//
//  * MPJPE: both poses translated so their roots coincide; mean joint distance.
//  * PA-MPJPE: the prediction aligned to the truth per frame by a similarity Procrustes
//    (rotation, translation, uniform scale; no reflection), estimated from all joints.
//  * N-MPJPE: both poses root-centred, the prediction scaled by the least-squares factor
//    s = Σ p·t / Σ p·p (scale only, Rhodin et al. 2018, as VideoPose3D's n_mpjpe).
//  * Acceleration error: a_t = x_{t+1} − 2 x_t + x_{t−1} of root-relative joints, mean
//    |a_pred − a_true| over frames 1..T−2 and joints (VIBE / HMMR). Jitter: mean |a_pred|.
//
// The root is excluded from the means by default (MetricOptions), as EVALUATION.md asks; with
// include_root = true PA-MPJPE equals VideoPose3D's p_mpjpe (mean over all joints). Any joint
// count works; the Body15 root is the default root. A non-finite coordinate is a bug upstream
// and throws std::invalid_argument rather than being averaged away.

#include <cstddef>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "core/body15.hpp"

namespace mocap::eval {

using PoseView = std::span<const glm::vec3>;     // one frame's joints, metres
using SequenceView = std::span<const PoseView>;  // frames in time order, equal joint counts

// Frame views of a sequence stored as arrays of joints (e.g. std::vector<Pose15>).
template <typename Frames>
std::vector<PoseView> frame_views(const Frames& frames) {
  std::vector<PoseView> views;
  views.reserve(frames.size());
  for (const auto& f : frames) views.emplace_back(f);
  return views;
}

struct MetricOptions {
  int root = index(Joint::root);
  bool include_root = false;  // count the root joint in the means
};

enum class Metric { mpjpe, pa_mpjpe, n_mpjpe };

// Errors of one frame: every joint's error (the root's too, for the breakdown) and the mean
// over the joints the options count.
struct JointErrors {
  std::vector<double> per_joint_mm;
  double mean_mm = 0.0;
};

JointErrors mpjpe(PoseView prediction, PoseView truth, const MetricOptions& options = {});
JointErrors pa_mpjpe(PoseView prediction, PoseView truth, const MetricOptions& options = {});
JointErrors n_mpjpe(PoseView prediction, PoseView truth, const MetricOptions& options = {});
JointErrors frame_errors(Metric metric, PoseView prediction, PoseView truth,
                         const MetricOptions& options = {});

// Sums per-frame errors: the overall mean (over frames and counted joints) and the per-joint
// means. Accumulators of several sequences merge into a mean over all their frames.
class ErrorAccumulator {
 public:
  void add(const JointErrors& frame);
  void merge(const ErrorAccumulator& other);

  std::size_t frames() const { return frames_; }
  double mean_mm() const;  // NaN when empty
  std::vector<double> per_joint_mean_mm() const;

 private:
  std::size_t frames_ = 0;
  double sum_ = 0.0;
  std::vector<double> per_joint_sum_;
};

// One metric over a whole sequence (prediction and truth of equal length).
ErrorAccumulator sequence_errors(Metric metric, SequenceView prediction, SequenceView truth,
                                 const MetricOptions& options = {});

// Acceleration error over frames 1..T−2 (nothing for T < 3). mm/frame² at the sequences' rate.
ErrorAccumulator acceleration_errors(SequenceView prediction, SequenceView truth,
                                     const MetricOptions& options = {});
// Jitter: the same with zero truth acceleration.
ErrorAccumulator jitter(SequenceView prediction, const MetricOptions& options = {});

// A mean of values with weights, e.g. per-sequence means weighted by frames (= the mean over all
// frames) or unweighted (every sequence counts once).
class MeanAccumulator {
 public:
  void add(double value, double weight = 1.0);
  void merge(const MeanAccumulator& other);
  double mean() const;  // NaN when empty
  double total_weight() const { return weight_; }
  std::size_t count() const { return count_; }

 private:
  double sum_ = 0.0;
  double weight_ = 0.0;
  std::size_t count_ = 0;
};

}  // namespace mocap::eval
