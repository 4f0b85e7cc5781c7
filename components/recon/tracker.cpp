#include "recon/tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

namespace mocap::recon {
namespace {

// Cost of a forbidden pair: larger than any sum of allowed costs (each at most the gate), so the
// assignment first maximises the allowed pairs.
constexpr float kForbidden = 1e6f;
// A detection with at least this many joints shows the whole person: its size replaces the
// track's. A partial one leaves a whole-person size alone (a half-hidden person keeps its full
// size) and may only enlarge a size not yet measured on the whole person.
constexpr int kWholePersonJoints = 12;
// Sizes below a pixel are noise (a single joint): never divide by them.
constexpr float kMinSize = 1.0f;
// Track::joint_seen of a joint that has only been guessed.
constexpr std::int64_t kNeverSeen = -1;
// The joints that move with the body, not swinging about it: the velocity is measured on them.
constexpr std::array<bool, kBodyJoints> kTorso = {
    true,                // head
    true,                // neck
    true, false, false,  // right shoulder, elbow, wrist
    true, false, false,  // left
    true, false, false,  // right hip, knee, ankle
    true, false, false,  // left
    true,                // root
};

// Typical length of each long bone as a fraction of a standing person's size (head top to ankles),
// from adult segment proportions: head 0.19, spine (root to neck) 0.30, upper arm 0.19, forearm
// 0.15, thigh and shin 0.25. Collarbones and pelvis halves are too short and too variable: 0.
// Indexed by the bone's child joint.
constexpr std::array<float, kBodyJoints> kBoneFraction = {
    0.19f, 0.30f,         // head, spine
    0.0f,  0.19f, 0.15f,  // right collarbone, upper arm, forearm
    0.0f,  0.19f, 0.15f,  // left
    0.0f,  0.25f, 0.25f,  // right pelvis half, thigh, shin
    0.0f,  0.25f, 0.25f,  // left
    0.0f,                 // root: no bone
};

// The person's size implied by its longest-looking bone. A bone seen at an angle looks shorter,
// never longer, so the largest estimate is the best: it tells the size of a person whose
// visible joints span only part of the body.
float bone_size(const std::array<glm::vec2, kBodyJoints>& position,
                const std::array<bool, kBodyJoints>& present) {
  float size = 0.0f;
  for (int j = 0; j < kBodyJoints; ++j) {
    const int parent = kJointParent[j];
    if (kBoneFraction[j] == 0.0f || !present[j] || !present[parent]) continue;
    size = std::max(size, glm::distance(position[j], position[parent]) / kBoneFraction[j]);
  }
  return size;
}

// Heights of the joints of a standing person of size 1 (head top to ankles) in image axes (y
// down), root at 0, from the same proportions as kBoneFraction. The guess puts every joint on
// the body's midline: left and right swap between front and back views, so the midline is as
// near to either as a guess can be.
constexpr std::array<float, kBodyJoints> kStandingHeight = {
    -0.49f, -0.30f,         // head, neck
    -0.28f, -0.09f, 0.06f,  // right shoulder, elbow, wrist
    -0.28f, -0.09f, 0.06f,  // left
    0.0f,   0.25f,  0.50f,  // right hip, knee, ankle
    0.0f,   0.25f,  0.50f,  // left
    0.0f,                   // root
};

float extent_size(const std::array<glm::vec2, kBodyJoints>& position,
                  const std::array<bool, kBodyJoints>& present) {
  glm::vec2 low(std::numeric_limits<float>::max());
  glm::vec2 high(std::numeric_limits<float>::lowest());
  bool any = false;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (!present[j]) continue;
    low = glm::min(low, position[j]);
    high = glm::max(high, position[j]);
    any = true;
  }
  return any ? std::max(high.x - low.x, high.y - low.y) : 0.0f;
}

}  // namespace

Tracker::Tracker(TrackerOptions options) : options_(options) {
  const float widest_gate = options_.gate + options_.gate_growth * options_.max_missed;
  if (!(options_.gate > 0.0f) || !(options_.gate_growth >= 0.0f) || !(widest_gate < 1000.0f) ||
      options_.max_missed < 0 || options_.min_common_joints < 1 ||
      options_.min_joints_to_start < 1 || !(options_.velocity_smoothing > 0.0f) ||
      options_.velocity_smoothing > 1.0f) {
    throw std::invalid_argument(
        "Tracker: needs gate > 0, gate_growth >= 0, gate + gate_growth * max_missed < 1000, "
        "max_missed >= 0, min_common_joints >= 1, min_joints_to_start >= 1, "
        "0 < velocity_smoothing <= 1");
  }
}

void Tracker::reset() { tracks_.clear(); }

std::vector<int> Tracker::update(std::span<const PersonKeypoints> people) {
  std::vector<int> ids(people.size());
  update(people, ids);
  return ids;
}

void Tracker::update(std::span<const PersonKeypoints> people, std::span<int> ids_out) {
  if (ids_out.size() != people.size()) {
    throw std::invalid_argument("Tracker::update: one id slot per person needed");
  }
  ++frame_;
  read_detections(people);
  fill_costs();
  const int detection_count = static_cast<int>(detections_.size());
  track_to_detection_.resize(tracks_.size());
  solver_.solve(costs_, static_cast<int>(tracks_.size()), detection_count, track_to_detection_);

  std::fill(ids_out.begin(), ids_out.end(), -1);
  detection_taken_.assign(detections_.size(), 0);
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    Track& track = tracks_[t];
    const int d = track_to_detection_[t];
    if (d >= 0 && costs_[t * detection_count + d] < kForbidden) {
      correct(track, detections_[d]);
      ids_out[d] = track.id;
      detection_taken_[d] = 1;
    } else {
      track.missed = static_cast<int>(frame_ - track.last_seen);
    }
  }
  retire_lost_tracks();
  for (int d = 0; d < detection_count; ++d) {
    if (detection_taken_[d] || detections_[d].present_count < options_.min_joints_to_start) {
      continue;
    }
    tracks_.push_back(start_track(detections_[d]));
    ids_out[d] = tracks_.back().id;
  }
}

void Tracker::read_detections(std::span<const PersonKeypoints> people) {
  detections_.resize(people.size());
  for (std::size_t i = 0; i < people.size(); ++i) {
    const PersonKeypoints& person = people[i];
    Detection& detection = detections_[i];
    detection.present_count = 0;
    for (int j = 0; j < kBodyJoints; ++j) {
      const float x = person.joints_xyc[3 * j];
      const float y = person.joints_xyc[3 * j + 1];
      const float confidence = person.joints_xyc[3 * j + 2];
      // Written so that NaN in any of the three fails the test.
      const bool present =
          std::isfinite(x) && std::isfinite(y) && confidence > options_.min_confidence;
      detection.present[j] = present;
      detection.position[j] = present ? glm::vec2(x, y) : glm::vec2(0.0f);
      detection.present_count += present ? 1 : 0;
    }
    const Box2D& box = person.box;
    const float box_size = box.width > 0 && box.height > 0
                               ? std::max(box.width, box.height)
                               : extent_size(detection.position, detection.present);
    detection.size = std::max(box_size, bone_size(detection.position, detection.present));
  }
}

void Tracker::fill_costs() {
  const std::size_t detection_count = detections_.size();
  costs_.resize(tracks_.size() * detection_count);
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    for (std::size_t d = 0; d < detection_count; ++d) {
      costs_[t * detection_count + d] = cost(tracks_[t], detections_[d]);
    }
  }
}

float Tracker::cost(const Track& track, const Detection& detection) const {
  const auto frames_ahead = static_cast<float>(frame_ - track.last_seen);
  const glm::vec2 shift = track.velocity * frames_ahead;
  // Joints seen recently (within max_missed frames of the track's last detection) are compared
  // when there are enough of them; otherwise all of the track's joints, including those carried
  // along for long and those guessed at its start: rough, but better than losing a person whose
  // visible joints change from frame to frame.
  float sums[2] = {0.0f, 0.0f};  // recent, all
  int counts[2] = {0, 0};
  for (int j = 0; j < kBodyJoints; ++j) {
    if (!detection.present[j]) continue;
    const float distance = glm::distance(track.position[j] + shift, detection.position[j]);
    const bool recent = track.joint_seen[j] != kNeverSeen &&
                        track.last_seen - track.joint_seen[j] <= options_.max_missed;
    sums[0] += recent ? distance : 0.0f;
    counts[0] += recent ? 1 : 0;
    sums[1] += distance;
    ++counts[1];
  }
  if (counts[1] == 0) return kForbidden;
  const int required = std::min(options_.min_common_joints, detection.present_count);
  const int used = counts[0] >= required ? 0 : 1;
  const float size = track.whole_size ? track.size : std::max(track.size, detection.size);
  const float cost = sums[used] / static_cast<float>(counts[used]) / std::max(size, kMinSize);
  return cost <= gate(track) ? cost : kForbidden;
}

float Tracker::gate(const Track& track) const {
  const auto frames_ahead = static_cast<float>(frame_ - track.last_seen);
  return options_.gate + options_.gate_growth * (frames_ahead - 1.0f);
}

glm::vec2 Tracker::measured_velocity(const Track& track, const Detection& detection) const {
  // Joints seen both then and now; joints that were only carried along by the old velocity would
  // just measure that velocity again. The torso alone when it is seen: limbs swing.
  glm::vec2 sums[2] = {glm::vec2(0.0f), glm::vec2(0.0f)};  // torso, limbs
  int counts[2] = {0, 0};
  for (int j = 0; j < kBodyJoints; ++j) {
    if (!detection.present[j] || track.joint_seen[j] != track.last_seen) continue;
    const int part = kTorso[j] ? 0 : 1;
    sums[part] += detection.position[j] - track.position[j];
    ++counts[part];
  }
  const int part = counts[0] > 0 ? 0 : 1;
  if (counts[part] == 0) return track.velocity;
  const auto frames_ahead = static_cast<float>(frame_ - track.last_seen);
  return sums[part] / (static_cast<float>(counts[part]) * frames_ahead);
}

void Tracker::correct(Track& track, const Detection& detection) const {
  const auto frames_ahead = static_cast<float>(frame_ - track.last_seen);
  const glm::vec2 old_velocity = track.velocity;
  const glm::vec2 velocity = measured_velocity(track, detection);
  track.velocity = track.hits == 1
                       ? velocity
                       : old_velocity + options_.velocity_smoothing * (velocity - old_velocity);
  for (int j = 0; j < kBodyJoints; ++j) {
    if (detection.present[j]) {
      track.position[j] = detection.position[j];
      track.joint_seen[j] = frame_;
    } else {
      track.position[j] += old_velocity * frames_ahead;
    }
  }
  update_size(track, detection);
  track.last_seen = frame_;
  track.missed = 0;
  ++track.hits;
}

void Tracker::update_size(Track& track, const Detection& detection) {
  if (detection.present_count >= kWholePersonJoints) {
    track.size = detection.size;
    track.whole_size = true;
  } else if (!track.whole_size) {
    track.size = std::max(track.size, detection.size);
  }
}

Track Tracker::start_track(const Detection& detection) {
  Track track;
  track.id = next_id_++;
  track.last_seen = frame_;
  track.hits = 1;
  update_size(track, detection);
  // Joints not seen yet are guessed from a standing person of the detection's size, placed so
  // that the seen joints fit it best (on average).
  const float size = std::max(track.size, kMinSize);
  const auto standing = [&](int j) { return glm::vec2(0.0f, size * kStandingHeight[j]); };
  glm::vec2 root_sum(0.0f);
  for (int j = 0; j < kBodyJoints; ++j) {
    if (detection.present[j]) root_sum += detection.position[j] - standing(j);
  }
  const glm::vec2 root = root_sum / static_cast<float>(detection.present_count);
  for (int j = 0; j < kBodyJoints; ++j) {
    const bool seen = detection.present[j];
    track.position[j] = seen ? detection.position[j] : root + standing(j);
    track.joint_seen[j] = seen ? frame_ : kNeverSeen;
  }
  return track;
}

void Tracker::retire_lost_tracks() {
  std::erase_if(tracks_, [&](const Track& t) { return t.missed > options_.max_missed; });
}

int count_id_switches(std::span<const std::vector<int>> gt_ids_per_frame,
                      std::span<const std::vector<int>> predicted_ids_per_frame) {
  if (gt_ids_per_frame.size() != predicted_ids_per_frame.size()) {
    throw std::invalid_argument("count_id_switches: different numbers of frames");
  }
  std::map<int, int> last_match;  // ground-truth id -> predicted id it was last matched to
  int switches = 0;
  for (std::size_t f = 0; f < gt_ids_per_frame.size(); ++f) {
    const std::vector<int>& gt = gt_ids_per_frame[f];
    const std::vector<int>& predicted = predicted_ids_per_frame[f];
    if (gt.size() != predicted.size()) {
      throw std::invalid_argument("count_id_switches: frame " + std::to_string(f) +
                                  " has different numbers of people");
    }
    for (std::size_t i = 0; i < gt.size(); ++i) {
      if (gt[i] < 0 || predicted[i] < 0) continue;
      const auto [it, first_time] = last_match.try_emplace(gt[i], predicted[i]);
      if (!first_time && it->second != predicted[i]) {
        ++switches;
        it->second = predicted[i];
      }
    }
  }
  return switches;
}

}  // namespace mocap::recon
