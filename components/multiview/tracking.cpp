#include "multiview/tracking.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

namespace mocap::multiview {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kForbidden = 1e6f;
// Bones a person and a track must both have for their lengths to be compared.
constexpr int kMinBonesCompared = 6;
// Bone sums are halved beyond this many sightings: old ones fade, the sum never overflows.
constexpr int kBoneMemory = 256;

static_assert(kJointParent[index(Joint::root)] == -1 && index(Joint::root) == kBodyBones,
              "bone b is joint b and its parent: the root must be the last joint");

}  // namespace

glm::vec3 body_centre(std::span<const TriangulatedPoint> body) {
  if (body[index(Joint::root)].valid()) return body[index(Joint::root)].position;
  glm::vec3 sum(0.0f);
  int n = 0;
  for (const TriangulatedPoint& p : body) {
    if (!p.valid()) continue;
    sum += p.position;
    ++n;
  }
  return n > 0 ? sum / static_cast<float>(n) : glm::vec3(kNaN);
}

std::array<float, kBodyBones> bone_lengths(std::span<const TriangulatedPoint> body) {
  std::array<float, kBodyBones> out{};
  for (int b = 0; b < kBodyBones; ++b) {
    const TriangulatedPoint& child = body[b];
    const TriangulatedPoint& parent = body[kJointParent[b]];
    out[b] =
        child.valid() && parent.valid() ? glm::distance(child.position, parent.position) : kNaN;
  }
  return out;
}

Tracker::Tracker(int keypoints, const TrackingOptions& options)
    : keypoints_(keypoints), options_(options) {
  if (keypoints <= 0 || !(options.fps > 0.0)) {
    throw std::invalid_argument("Tracker: needs keypoints > 0 and fps > 0");
  }
}

void Tracker::reset() {
  tracks_.clear();
  predicted_.clear();
  updated_.clear();
  next_id_ = 0;
}

void Tracker::begin_frame(std::int64_t frame) {
  frame_ = frame;
  const double forget = options_.forget_after_s * options_.fps;
  std::erase_if(tracks_,
                [&](const Track& t) { return static_cast<double>(frame - t.last_frame) > forget; });
  const auto extrapolation =
      std::max<std::int64_t>(1, std::lround(options_.max_extrapolation_s * options_.fps));
  const std::size_t k_count = static_cast<std::size_t>(keypoints_);
  predicted_.assign(tracks_.size() * k_count, glm::vec3(kNaN));
  sigma_.assign(tracks_.size() * k_count, 0.0f);
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    const Track& track = tracks_[t];
    for (std::size_t k = 0; k < k_count; ++k) {
      const std::int64_t ahead = frame - track.keypoint_frame[k];
      if (ahead > extrapolation) continue;  // too stale to predict from
      predicted_[t * k_count + k] =
          track.keypoints[k] + track.velocity[k] * static_cast<float>(ahead);
      if (track.hits >= options_.min_hits) {
        sigma_[t * k_count + k] =
            std::sqrt(track.spread[k]) * static_cast<float>(std::max<std::int64_t>(ahead, 1));
      }
    }
  }
  updated_.assign(tracks_.size(), 0);
}

std::span<const glm::vec3> Tracker::prediction(int t) const {
  return std::span<const glm::vec3>(predicted_)
      .subspan(static_cast<std::size_t>(t) * keypoints_, static_cast<std::size_t>(keypoints_));
}

std::span<const float> Tracker::prediction_sigma(int t) const {
  return std::span<const float>(sigma_).subspan(static_cast<std::size_t>(t) * keypoints_,
                                                static_cast<std::size_t>(keypoints_));
}

float Tracker::gate(int t) const {
  const auto missed =
      static_cast<float>(std::max<std::int64_t>(frame_ - track(t).last_frame - 1, 0));
  return std::min(options_.max_gate_m, options_.gate_m + options_.gate_growth_m * missed);
}

void Tracker::start(int t, const TrackInput& person) {
  Track& track = tracks_[static_cast<std::size_t>(t)];
  const glm::vec3 centre = body_centre(person.body);
  if (track.hits > 0 && std::isfinite(centre.x) && frame_ > track.last_frame) {
    const glm::vec3 measured =
        (centre - track.centre) / static_cast<float>(frame_ - track.last_frame);
    track.centre_velocity =
        track.hits == 1 ? measured
                        : glm::mix(track.centre_velocity, measured, options_.velocity_smoothing);
  }
  if (std::isfinite(centre.x)) track.centre = centre;
  const auto extrapolation =
      std::max<std::int64_t>(1, std::lround(options_.max_extrapolation_s * options_.fps));
  const float floor = options_.min_sigma_m * options_.min_sigma_m;
  for (std::size_t k = 0; k < static_cast<std::size_t>(keypoints_); ++k) {
    if (!person.keypoints[k].valid()) continue;
    const glm::vec3 now = person.keypoints[k].position;
    const std::int64_t ahead = frame_ - track.keypoint_frame[k];
    if (ahead > 0 && ahead <= extrapolation) {
      const glm::vec3 measured = (now - track.keypoints[k]) / static_cast<float>(ahead);
      track.velocity[k] = track.hits <= 1
                              ? measured
                              : glm::mix(track.velocity[k], measured, options_.velocity_smoothing);
    } else {
      track.velocity[k] = track.centre_velocity;
    }
    if (!person.innovations.empty() && std::isfinite(person.innovations[k]) && ahead > 0) {
      const float per_frame = person.innovations[k] / static_cast<float>(ahead);
      track.spread[k] = std::max(
          floor, glm::mix(track.spread[k], per_frame * per_frame / 3.0f, options_.sigma_learning));
    }
    track.keypoints[k] = now;
    track.keypoint_frame[k] = frame_;
  }
  const std::array<float, kBodyBones> bones = bone_lengths(person.body);
  for (int b = 0; b < kBodyBones; ++b) {
    if (!std::isfinite(bones[b])) continue;
    if (track.bone_count[b] >= kBoneMemory) {
      track.bone_sum[b] *= 0.5f;
      track.bone_count[b] /= 2;
    }
    track.bone_sum[b] += bones[b];
    ++track.bone_count[b];
  }
  track.last_frame = frame_;
  ++track.hits;
  updated_[static_cast<std::size_t>(t)] = 1;
}

void Tracker::update(int t, const TrackInput& person) { start(t, person); }

float Tracker::bone_difference(const Track& track, std::span<const TriangulatedPoint> body) const {
  const std::array<float, kBodyBones> bones = bone_lengths(body);
  float sum = 0.0f;
  int n = 0;
  for (int b = 0; b < kBodyBones; ++b) {
    if (!std::isfinite(bones[b]) || track.bone_count[b] == 0) continue;
    sum += std::abs(bones[b] - track.bone_sum[b] / static_cast<float>(track.bone_count[b]));
    ++n;
  }
  return n >= kMinBonesCompared ? sum / static_cast<float>(n) : kNaN;
}

void Tracker::place_new(std::span<const TrackInput> people, std::span<int> tracks) {
  missing_.clear();
  for (int t = 0; t < size(); ++t) {
    if (!updated_[t] && track(t).hits >= options_.min_hits) missing_.push_back(t);
  }
  const int rows = static_cast<int>(people.size()), cols = static_cast<int>(missing_.size());
  cost_.assign(static_cast<std::size_t>(rows) * cols, kForbidden);
  for (int p = 0; p < rows; ++p) {
    const glm::vec3 centre = body_centre(people[p].body);
    if (!std::isfinite(centre.x)) continue;
    for (int m = 0; m < cols; ++m) {
      const Track& track = tracks_[static_cast<std::size_t>(missing_[m])];
      const float away_s =
          static_cast<float>(static_cast<double>(frame_ - track.last_frame) / options_.fps);
      const float reach = options_.return_margin_m + options_.max_speed_mps * away_s;
      const float distance = glm::distance(centre, track.centre);
      const float bones = bone_difference(track, people[p].body);
      if (distance > reach || bones > options_.bone_tolerance_m) continue;
      cost_[static_cast<std::size_t>(p) * cols + m] =
          distance / reach + (std::isfinite(bones) ? bones / options_.bone_tolerance_m : 1.0f);
    }
  }
  assignment_.assign(people.size(), -1);
  if (rows > 0 && cols > 0) solver_.solve(cost_, rows, cols, assignment_);
  for (int p = 0; p < rows; ++p) {
    const int m = assignment_[p];
    if (m >= 0 && cost_[static_cast<std::size_t>(p) * cols + m] < kForbidden) {
      start(missing_[m], people[p]);
      tracks[p] = missing_[m];
      continue;
    }
    Track& track = tracks_.emplace_back();
    track.id = next_id_++;
    const std::size_t k_count = static_cast<std::size_t>(keypoints_);
    track.keypoints.assign(k_count, glm::vec3(kNaN));
    track.keypoint_frame.assign(k_count, std::numeric_limits<std::int64_t>::min() / 2);
    track.velocity.assign(k_count, glm::vec3(0.0f));
    track.spread.assign(k_count, options_.initial_sigma_m * options_.initial_sigma_m);
    track.last_frame = frame_;
    updated_.push_back(0);
    start(size() - 1, people[p]);
    tracks[p] = size() - 1;
  }
}

void Tracker::end_frame() {
  std::size_t kept = 0;
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    if (!updated_[t] && tracks_[t].hits < options_.min_hits) continue;
    if (kept != t) tracks_[kept] = std::move(tracks_[t]);
    ++kept;
  }
  tracks_.resize(kept);
}

}  // namespace mocap::multiview
