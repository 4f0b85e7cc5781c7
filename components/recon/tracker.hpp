#pragma once
// Multi-person tracking by keypoints: gives every person a stable id across frames.
//
// Per frame, each live track predicts where its joints are now with a constant velocity: the
// whole person moves by the track's velocity per frame. Limbs are not extrapolated one by one,
// because a swinging limb's velocity is wrong a few frames later; for the same reason the
// velocity is measured on the torso (head, neck, shoulders, hips, root) when any of it is seen.
//
// The cost of pairing a track with a detected person is the mean distance between predicted and
// detected positions over the joints both have (those the track saw recently, when there are
// enough), divided by the person's size (the longer side of
// the box). The size is the track's own once it has seen the whole person, so a small person's
// track does not look close to a large person nearby; before that, the larger of the track's and
// the detection's. Pairs that share too few joints, or cost more than the gate, are forbidden.
// The gate widens while a track goes undetected, as its prediction gets less certain. The
// Hungarian method then finds the pairing with the most allowed pairs and, among those, the
// least total cost.
//
// A detection left over starts a new track with a new id when it shows enough joints; a track
// left over keeps predicting and survives max_missed frames without a detection. Ids start at 0,
// grow in order of first appearance and are never reused. Everything is deterministic: no
// randomness, no hashing, ties broken by position in the lists.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec2.hpp>

#include "core/body15.hpp"
#include "core/messages.hpp"
#include "recon/hungarian.hpp"

namespace mocap::recon {

struct TrackerOptions {
  // Largest cost (mean joint distance / person size) taken as the same person one frame after
  // the last detection. A person walking at 1.5 m/s moves 3 % of their height per frame at 30 fps
  // and constant velocity predicts most of that; two people side by side are about 25 % apart.
  // The optimal assignment separates neighbours; the gate refuses pairs that are clearly not the
  // same person, which would otherwise be taken just to pair more tracks.
  float gate = 0.25f;
  // Added to the gate per further frame without a detection (0.5 after 10 missed frames).
  float gate_growth = 0.025f;
  // Frames a track lives on without a detection (0.33–0.42 s at 24–30 fps): long enough for a
  // person to pass behind another, short enough that a new person at that spot gets a new id.
  int max_missed = 10;
  // Recently seen joints a track and a detection must share to be compared on those alone (fewer
  // when the detection has fewer); otherwise all of the track's joints, older and guessed ones
  // included, are compared.
  int min_common_joints = 3;
  // Joints a detection needs to start a new track; sparser leftovers get id −1: a person seen
  // by one or two joints cannot be reconstructed, and a track born from them could not be
  // compared with the next frame's detection, which shows other joints.
  int min_joints_to_start = 4;
  // Weight of the newest velocity measurement in the track's velocity (1: no smoothing).
  float velocity_smoothing = 0.5f;
  // Keypoints with a confidence at or below this count as missing (as do NaN coordinates).
  float min_confidence = 0.0f;
};

// One detected person: the 15 body joints in image pixels and the person's box.
struct PersonKeypoints {
  std::array<float, kBodyJoints * 3> joints_xyc{};  // x, y, confidence per joint (Body15 order)
  Box2D box;  // empty (width or height <= 0): the extent of the present joints is used instead
};

struct Track {
  int id = -1;
  std::int64_t last_seen = 0;  // frame of the last detection
  int missed = 0;              // consecutive frames without a detection
  int hits = 0;                // frames with a detection
  float size = 0.0f;           // person size in pixels (longer side of the box)
  bool whole_size = false;     // size measured on a (nearly) whole person
  glm::vec2 velocity{0.0f};    // pixels per frame, of the whole person
  // Joint positions at frame last_seen: detected, or carried along by the velocity when the
  // joint was missing. Joints detected in the max_missed frames up to last_seen are preferred
  // when comparing.
  std::array<glm::vec2, kBodyJoints> position{};
  std::array<std::int64_t, kBodyJoints>
      joint_seen{};  // frame the joint was last detected; -1: never
};

class Tracker {
 public:
  // Throws std::invalid_argument for options outside their ranges.
  explicit Tracker(TrackerOptions options = {});

  // Consumes the next frame: ids_out[i] receives the id of people[i] (same size), or −1 for a
  // person matching no track and too sparse to start one. Call it for every frame, with no
  // people when a frame has none. Allocates nothing once the largest frame has been seen.
  void update(std::span<const PersonKeypoints> people, std::span<int> ids_out);
  std::vector<int> update(std::span<const PersonKeypoints> people);

  // The live tracks, oldest first (seen this frame or missed for at most max_missed frames).
  std::span<const Track> tracks() const { return tracks_; }
  std::int64_t frames() const { return frame_ + 1; }  // frames consumed so far
  const TrackerOptions& options() const { return options_; }
  // Forgets every track; ids continue from where they were, so they stay unique.
  void reset();

 private:
  struct Detection {
    std::array<glm::vec2, kBodyJoints> position;
    std::array<bool, kBodyJoints> present;
    int present_count;
    float size;
  };

  void read_detections(std::span<const PersonKeypoints> people);
  void fill_costs();
  float cost(const Track& track, const Detection& detection) const;
  float gate(const Track& track) const;
  void correct(Track& track, const Detection& detection) const;
  static void update_size(Track& track, const Detection& detection);
  glm::vec2 measured_velocity(const Track& track, const Detection& detection) const;
  Track start_track(const Detection& detection);
  void retire_lost_tracks();

  TrackerOptions options_;
  std::int64_t frame_ = -1;
  int next_id_ = 0;
  std::vector<Track> tracks_;
  // Per-frame scratch, kept to avoid allocations.
  std::vector<Detection> detections_;
  std::vector<float> costs_;  // tracks × detections
  std::vector<int> track_to_detection_;
  std::vector<char> detection_taken_;
  AssignmentSolver solver_;
};

// Identity switches in the MOT (CLEAR MOT) sense: for each ground-truth person, the number of
// times the predicted id it is matched to differs from the one it was last matched to (frames
// where it is absent or unmatched do not reset that memory). Frame f lists ground-truth ids and
// predicted ids of the same people in the same order; −1 on either side means no person or no
// id, and the pair is skipped. Throws std::invalid_argument when the two do not line up.
int count_id_switches(std::span<const std::vector<int>> gt_ids_per_frame,
                      std::span<const std::vector<int>> predicted_ids_per_frame);

}  // namespace mocap::recon
