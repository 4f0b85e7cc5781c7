#pragma once
// People tracked in 3D across frames: ids stable over time, each track's prediction for the next
// frame (which the association tries first), and people who come back.
//
// - Prediction: each keypoint at constant velocity (its own, smoothed; the body centre's until it
//   has one). Extrapolation stops after `max_extrapolation_s`. Each keypoint also learns how far
//   off its predictions are (the innovation of well-seen keypoints), so the triangulation can use
//   the prediction as one more measurement of the right weight (person_triangulation.hpp): a
//   joint seen by two nearly opposite cameras gets its depth from the track.
// - A new track must be seen in `min_hits` frames before it is confirmed (the reconstructor
//   reports people of unconfirmed tracks only on request) and before it survives a frame without
//   a sighting: a chance agreement of false detections in two views lives one frame.
// - A person who is not seen (hidden from all but one view, out of the rig's sight) keeps their
//   track for `forget_after_s`. A person appearing meanwhile, not predicted by any track, gets the
//   id of a missing track when their body centre is within reach of where that track was last seen
//   (return_margin_m + max_speed_mps × the time away) and their bone lengths match the track's
//   (mean difference of the 14 body bones within `bone_tolerance_m`), the best pairs chosen by the
//   Hungarian method. After forget_after_s the track is gone and a returning person gets a new id:
//   beyond a few seconds the reachable region covers the whole room and bone lengths alone (a few
//   centimetres apart between adults, measured with centimetres of noise) cannot tell people
//   apart, and a wrong id is worse than a new one.
// Ids start at 0, grow in order of creation and are never reused. Deterministic.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "core/body15.hpp"
#include "multiview/triangulation.hpp"
#include "recon/hungarian.hpp"

namespace mocap::multiview {

struct TrackingOptions {
  double fps = 30.0;  // frame numbers to seconds
  // Largest detection-to-prediction cost (metres, detections.hpp) for a track's detection in a
  // view, one frame after its last sighting; grows by gate_growth_m per further frame up to
  // max_gate_m. (Costs are capped at RayCostOptions::cap_m: a gate that high would let a track
  // lost for seconds take any detection; a person back after a while is recognised by
  // place_new's reach and bones instead.)
  float gate_m = 0.25f;
  float gate_growth_m = 0.02f;
  float max_gate_m = 0.4f;
  // Weight of the newest velocity measurement (1: no smoothing). 0.3 / 0.5 / 1 gave 29.7 / 30.7 /
  // 34.0 mm MPJPE on the virtual scenes (4 views, 3 people, σ 2 %; docs/multiview.md).
  float velocity_smoothing = 0.3f;
  // Whether the triangulation uses the predictions at all (off: a tracked person's keypoints are
  // the views' alone, as without tracking).
  bool prior = true;
  // A new keypoint's prediction error (sigma per axis, metres) until it has been measured, the
  // weight of each new measurement of it (squared innovations of well-seen keypoints; 0.05 / 0.1
  // / 0.3 gave 32.2 / 30.7 / 28.9 mm there), and its floor.
  float initial_sigma_m = 0.1f;
  float sigma_learning = 0.3f;
  float min_sigma_m = 0.01f;
  // Predictions go no further ahead than this.
  float max_extrapolation_s = 0.5f;
  // Frames with a sighting that confirm a track.
  int min_hits = 3;
  // A track unseen for longer is forgotten; until then a person within reach (return_margin_m +
  // max_speed_mps × the time away) with bone lengths within bone_tolerance_m gets its id back.
  float forget_after_s = 3.0f;
  float max_speed_mps = 2.5f;
  float return_margin_m = 0.5f;
  float bone_tolerance_m = 0.04f;
};

inline constexpr int kBodyBones = kBodyJoints - 1;

struct Track {
  int id = -1;
  std::int64_t last_frame = 0;               // frame of the last sighting
  int hits = 0;                              // frames with a sighting
  std::vector<glm::vec3> keypoints;          // where each keypoint was last triangulated
  std::vector<std::int64_t> keypoint_frame;  // and when
  std::vector<glm::vec3> velocity;           // per keypoint, metres per frame
  std::vector<float> spread;  // per keypoint: prediction error variance one frame ahead, per axis
  glm::vec3 centre{0.0f};     // body centre at last_frame
  glm::vec3 centre_velocity{0.0f};           // metres per frame
  std::array<float, kBodyBones> bone_sum{};  // bone lengths summed over sightings
  std::array<int, kBodyBones> bone_count{};
};

// A person reconstructed in the current frame, as the tracker needs it.
struct TrackInput {
  std::span<const TriangulatedPoint> keypoints;
  std::span<const TriangulatedPoint> body;  // the 15 body joints
  // Per keypoint, how far the views' own point was from the prediction (NaN: not measured);
  // may be empty.
  std::span<const float> innovations;
};

class Tracker {
 public:
  Tracker(int keypoints, const TrackingOptions& options);

  // Forgets tracks unseen for too long and predicts every track for `frame`.
  void begin_frame(std::int64_t frame);
  int size() const { return static_cast<int>(tracks_.size()); }
  const Track& track(int t) const { return tracks_[static_cast<std::size_t>(t)]; }
  // Track t's keypoints predicted for this frame (NaN: unknown).
  std::span<const glm::vec3> prediction(int t) const;
  // The standard deviation per axis of each predicted keypoint (metres); 0 for a track too young
  // to predict reliably (fewer than min_hits sightings).
  std::span<const float> prediction_sigma(int t) const;
  // Its gate for this frame (TrackingOptions::gate_m).
  float gate(int t) const;

  // Track t was seen this frame as `person`.
  void update(int t, const TrackInput& person);
  // People of this frame that no track predicted: each continues a missing track, or starts a
  // new one; tracks[i] gets the track index of people[i].
  void place_new(std::span<const TrackInput> people, std::span<int> tracks);
  // Seen in min_hits frames: a chance agreement of false detections is not.
  bool confirmed(int t) const { return track(t).hits >= options_.min_hits; }
  // Drops unconfirmed tracks that were not seen this frame.
  void end_frame();

  void reset();

 private:
  void start(int t, const TrackInput& person);
  float bone_difference(const Track& track, std::span<const TriangulatedPoint> body) const;

  int keypoints_;
  TrackingOptions options_;
  std::int64_t frame_ = 0;
  int next_id_ = 0;
  std::vector<Track> tracks_;
  std::vector<glm::vec3> predicted_;  // tracks × keypoints
  std::vector<float> sigma_;          // tracks × keypoints
  std::vector<char> updated_;
  std::vector<float> cost_;
  std::vector<int> missing_;
  std::vector<int> assignment_;
  recon::AssignmentSolver solver_;
};

// The body centre of a person: the root joint, else the mean of the triangulated body joints;
// NaN when none.
glm::vec3 body_centre(std::span<const TriangulatedPoint> body);
// The 14 bone lengths (kJointParent), NaN where a joint is missing.
std::array<float, kBodyBones> bone_lengths(std::span<const TriangulatedPoint> body);

}  // namespace mocap::multiview
