#pragma once
// HumanEva-I with its calibrated cameras, reconstructed from several views at once (issue 19,
// report 3; docs/evaluation-cameras.md "HumanEva-I from several cameras"): the Validate chunks of
// the monocular protocol (humaneva_protocol.hpp), each seen by two or three of C1-C3, their
// ground-truth 2D with the same noise each camera's monocular run gets, reconstructed by
// components/multiview (association, triangulation, tracking; the library's defaults) and then
// fitted with the multi-view skeleton fit (fit_multiview_sequence through fit::fit_tracks).
//
// Scored as the monocular protocol scores (eval::score: MPJPE root-aligned and PA-MPJPE over the
// 14 non-root joints, acceleration error), plus what only several views give: the absolute MPJPE
// in HumanEva's world (no alignment, 15 joints), and the bone-length std of the multi-view
// protocol (add_track_metrics). Library mocap_eval_humaneva_multiview: it needs the fit, which
// mocap_eval must not depend on.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/ground_plane.hpp"
#include "eval/humaneva_protocol.hpp"
#include "eval/multiview_scene.hpp"
#include "fit/monocular_prior.hpp"
#include "multiview/reconstructor.hpp"

namespace mocap::eval {

// One Validate chunk through all three cameras: the monocular protocol's sequences of that chunk.
struct HumanEvaTake {
  std::array<std::size_t, io::humaneva::kCameras> sequence{};  // C1..C3: index in the list
  std::vector<Body> truth_world;  // HumanEva's world (Z up), metres, at the evaluation rate
  GroundPlane floor;              // the subject's rig's floor (world Z = 0)
};

// Groups humaneva_validation_sequences()'s list (chunk by chunk, cameras C1..C3 in turn) into
// takes, each with its subject's floor. Throws std::invalid_argument when a chunk does not have
// its three cameras in order, InputError when a subject's rig has no floor.
std::vector<HumanEvaTake> humaneva_takes(const std::vector<HumanEvaSequence>& sequences,
                                         const HumanEvaCameras& cameras);

// "C1+C3" for camera indices {0, 2}.
std::string cameras_label(std::span<const int> cameras);

struct HumanEvaMultiviewOptions {
  // The library's defaults; tracker.fps is set to `fps` (the rate the frames are at).
  multiview::ReconstructionOptions reconstruction;
  double fps = 24.0;
  bool fit = true;  // also fit_multiview_sequence (full mode) on the tracks
  // With fit: also the fit with the monocular retrieval's prior (fit::MonocularPrior) from this
  // database (none: no such row).
  const posedb::Database* prior_db = nullptr;
  fit::MonocularPriorOptions prior;
};

// One take reconstructed from some cameras. Poses are in HumanEva's world (the rig's), valid
// where the subject was reconstructed with all 15 joints (a person missing joints, or none, is
// not scored: the frame counts against coverage).
struct TakeReconstruction {
  std::vector<recon::Pose3D> triangulated;  // tracking on (the library's default)
  std::vector<recon::Pose3D> fitted;        // empty without options.fit
  std::vector<recon::Pose3D> fitted_prior;  // + the monocular prior; empty without prior_db
  long extra_people = 0;                    // people reported besides the one scored, summed
  long partial_frames = 0;                  // frames whose person missed a joint
};

// `inputs` holds each camera's 2D (C1..C3, all three, noisy or not); `cameras` which of them the
// reconstruction sees. The person scored in a frame is the one seen in the most views (the first
// of those on a tie): HumanEva shows one subject.
TakeReconstruction reconstruct_take(const HumanEvaTake& take,
                                    const std::vector<HumanEvaSequence>& sequences,
                                    std::span<const std::vector<recon::BodyXyc>> inputs,
                                    std::span<const int> cameras,
                                    const HumanEvaMultiviewOptions& options);

// Scores of one reconstruction of a take against `truth` (the same frame as the poses).
struct TakeScores {
  Scores pose;            // eval::score on the frames kept
  double absolute_m = 0;  // Σ over frames of the mean distance of the 15 joints, no alignment
  long absolute_frames = 0;
  std::vector<ScenePersonTrack> tracks;  // one per take, frames kept: add_track_metrics
  void add(const TakeScores& other);
};

// `keep` (optional, one per frame): only those frames are scored, so that every row of a table
// is scored on the frames all rows reconstructed. `absolute`: the poses are placed (multi-view),
// not root-relative (monocular).
TakeScores score_take(const std::vector<recon::Pose3D>& poses, const std::vector<Body>& truth,
                      const std::vector<char>* keep, bool absolute);

}  // namespace mocap::eval
