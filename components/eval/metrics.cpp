#include "eval/metrics.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "eval/procrustes.hpp"

namespace mocap::eval {
namespace {

constexpr double kMillimetres = 1000.0;

void check_frame(PoseView pose, std::size_t joints, const char* what,
                 const MetricOptions& options) {
  if (pose.size() != joints) {
    throw std::invalid_argument(std::string(what) + " has " + std::to_string(pose.size()) +
                                " joints, expected " + std::to_string(joints));
  }
  for (std::size_t j = 0; j < pose.size(); ++j) {
    const glm::vec3& p = pose[j];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      throw std::invalid_argument(std::string(what) + " joint " + std::to_string(j) +
                                  " is not finite");
    }
  }
  if (options.root < 0 || static_cast<std::size_t>(options.root) >= joints) {
    throw std::invalid_argument("root index " + std::to_string(options.root) +
                                " is outside the pose");
  }
  const std::size_t counted = options.include_root ? joints : joints - 1;
  if (counted == 0) throw std::invalid_argument("no joint left to average");
}

void check_pair(PoseView prediction, PoseView truth, const MetricOptions& options) {
  check_frame(truth, truth.size(), "truth", options);
  check_frame(prediction, truth.size(), "prediction", options);
}

// Joints relative to the root, in double precision.
std::vector<glm::dvec3> root_relative(PoseView pose, int root) {
  std::vector<glm::dvec3> out(pose.size());
  const glm::dvec3 r(pose[root]);
  for (std::size_t j = 0; j < pose.size(); ++j) out[j] = glm::dvec3(pose[j]) - r;
  return out;
}

std::vector<glm::dvec3> as_double(PoseView pose) {
  return std::vector<glm::dvec3>(pose.begin(), pose.end());
}

JointErrors distances(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b,
                      const MetricOptions& options) {
  JointErrors out;
  out.per_joint_mm.resize(a.size());
  double sum = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j) {
    out.per_joint_mm[j] = glm::length(a[j] - b[j]) * kMillimetres;
    if (options.include_root || static_cast<int>(j) != options.root) sum += out.per_joint_mm[j];
  }
  const std::size_t counted = options.include_root ? a.size() : a.size() - 1;
  out.mean_mm = sum / static_cast<double>(counted);
  return out;
}

void check_sequences(SequenceView prediction, SequenceView truth) {
  if (prediction.size() != truth.size()) {
    throw std::invalid_argument("prediction has " + std::to_string(prediction.size()) +
                                " frames, truth " + std::to_string(truth.size()));
  }
}

// a_t of root-relative joints for t = 1..T-2 of one sequence, frame t-1 at index t-1.
std::vector<std::vector<glm::dvec3>> accelerations(SequenceView sequence, std::size_t joints,
                                                   const char* what, const MetricOptions& options) {
  std::vector<std::vector<glm::dvec3>> relative;
  relative.reserve(sequence.size());
  for (const PoseView& frame : sequence) {
    check_frame(frame, joints, what, options);
    relative.push_back(root_relative(frame, options.root));
  }
  std::vector<std::vector<glm::dvec3>> out;
  for (std::size_t t = 1; t + 1 < relative.size(); ++t) {
    std::vector<glm::dvec3> a(joints);
    for (std::size_t j = 0; j < joints; ++j) {
      a[j] = relative[t + 1][j] - 2.0 * relative[t][j] + relative[t - 1][j];
    }
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace

JointErrors mpjpe(PoseView prediction, PoseView truth, const MetricOptions& options) {
  check_pair(prediction, truth, options);
  return distances(root_relative(prediction, options.root), root_relative(truth, options.root),
                   options);
}

JointErrors pa_mpjpe(PoseView prediction, PoseView truth, const MetricOptions& options) {
  check_pair(prediction, truth, options);
  std::vector<glm::dvec3> p = as_double(prediction);
  const std::vector<glm::dvec3> t = as_double(truth);
  const Similarity fit = procrustes(p, t);
  for (auto& x : p) x = fit.apply(x);
  return distances(p, t, options);
}

JointErrors n_mpjpe(PoseView prediction, PoseView truth, const MetricOptions& options) {
  check_pair(prediction, truth, options);
  std::vector<glm::dvec3> p = root_relative(prediction, options.root);
  const std::vector<glm::dvec3> t = root_relative(truth, options.root);
  double pt = 0.0, pp = 0.0;
  for (std::size_t j = 0; j < p.size(); ++j) pt += glm::dot(p[j], t[j]), pp += glm::dot(p[j], p[j]);
  const double scale = pp > 0.0 ? pt / pp : 1.0;  // a collapsed prediction cannot be scaled
  for (auto& x : p) x *= scale;
  return distances(p, t, options);
}

JointErrors frame_errors(Metric metric, PoseView prediction, PoseView truth,
                         const MetricOptions& options) {
  switch (metric) {
    case Metric::mpjpe:
      return mpjpe(prediction, truth, options);
    case Metric::pa_mpjpe:
      return pa_mpjpe(prediction, truth, options);
    case Metric::n_mpjpe:
      return n_mpjpe(prediction, truth, options);
  }
  throw std::invalid_argument("unknown metric");
}

void ErrorAccumulator::add(const JointErrors& frame) {
  if (frames_ == 0 && per_joint_sum_.empty()) per_joint_sum_.assign(frame.per_joint_mm.size(), 0.0);
  if (frame.per_joint_mm.size() != per_joint_sum_.size()) {
    throw std::invalid_argument("ErrorAccumulator: frames with different joint counts");
  }
  for (std::size_t j = 0; j < per_joint_sum_.size(); ++j)
    per_joint_sum_[j] += frame.per_joint_mm[j];
  sum_ += frame.mean_mm;
  ++frames_;
}

void ErrorAccumulator::merge(const ErrorAccumulator& other) {
  if (other.frames_ == 0) return;
  if (frames_ == 0) {
    *this = other;
    return;
  }
  if (other.per_joint_sum_.size() != per_joint_sum_.size()) {
    throw std::invalid_argument("ErrorAccumulator: merging different joint counts");
  }
  for (std::size_t j = 0; j < per_joint_sum_.size(); ++j)
    per_joint_sum_[j] += other.per_joint_sum_[j];
  sum_ += other.sum_;
  frames_ += other.frames_;
}

double ErrorAccumulator::mean_mm() const {
  return frames_ == 0 ? std::numeric_limits<double>::quiet_NaN()
                      : sum_ / static_cast<double>(frames_);
}

std::vector<double> ErrorAccumulator::per_joint_mean_mm() const {
  std::vector<double> out(per_joint_sum_.size());
  for (std::size_t j = 0; j < out.size(); ++j)
    out[j] = per_joint_sum_[j] / static_cast<double>(frames_);
  return out;
}

ErrorAccumulator sequence_errors(Metric metric, SequenceView prediction, SequenceView truth,
                                 const MetricOptions& options) {
  check_sequences(prediction, truth);
  ErrorAccumulator acc;
  for (std::size_t t = 0; t < truth.size(); ++t) {
    acc.add(frame_errors(metric, prediction[t], truth[t], options));
  }
  return acc;
}

ErrorAccumulator acceleration_errors(SequenceView prediction, SequenceView truth,
                                     const MetricOptions& options) {
  check_sequences(prediction, truth);
  ErrorAccumulator acc;
  if (truth.empty()) return acc;
  const std::size_t joints = truth[0].size();
  const auto a_pred = accelerations(prediction, joints, "prediction", options);
  const auto a_true = accelerations(truth, joints, "truth", options);
  for (std::size_t t = 0; t < a_true.size(); ++t) acc.add(distances(a_pred[t], a_true[t], options));
  return acc;
}

ErrorAccumulator jitter(SequenceView prediction, const MetricOptions& options) {
  ErrorAccumulator acc;
  if (prediction.empty()) return acc;
  const std::size_t joints = prediction[0].size();
  const std::vector<glm::dvec3> zero(joints, glm::dvec3(0.0));
  for (const auto& a : accelerations(prediction, joints, "prediction", options)) {
    acc.add(distances(a, zero, options));
  }
  return acc;
}

void MeanAccumulator::add(double value, double weight) {
  if (!(weight >= 0.0) || !std::isfinite(weight)) {
    throw std::invalid_argument("MeanAccumulator: weight must be finite and >= 0");
  }
  sum_ += value * weight;
  weight_ += weight;
  ++count_;
}

void MeanAccumulator::merge(const MeanAccumulator& other) {
  sum_ += other.sum_;
  weight_ += other.weight_;
  count_ += other.count_;
}

double MeanAccumulator::mean() const {
  return weight_ > 0.0 ? sum_ / weight_ : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace mocap::eval
