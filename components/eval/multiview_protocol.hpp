#pragma once
// The virtual multi-view protocol (../shared/docs/EVALUATION.md "Multi-view", issue 19 report 2):
// people of the *held-out* CMU clips placed together in one room (eval/multiview_scene.hpp), seen
// by 2-16 cameras on a ring, their 2D keypoints degraded (noise as a fraction of the box height,
// dropped joints, outlier keypoints, false detections, people hiding each other), reconstructed by
//   (i)   the baseline: confidence-weighted DLT with Pose2Sim's camera-exclusion rule, per frame;
//   (ii)  ours per frame (association + robust triangulation, no tracking);
//   (iii) ours with tracking in 3D;
//   (iv)  + skeleton fit on all views over (iii)'s tracks (fit::fit_tracks with
//         fit::multiview_fit_defaults(), weights chosen on train scenes), full and live.
// and scored in the world frame: MPJPE (no alignment), PA-MPJPE, acceleration error, bone-length
// standard deviation, wrong associations, id switches, coverage.
//
// Nothing here is chosen on the held-out clips: the reconstruction runs with its defaults (set on
// train clips, tools/bench/multiview_bench.cpp), the scene's layout is the benchmark's (a 6 m
// ring, 2 and 3 cameras 90 degrees apart), people take the longest held-out clips.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "eval/multiview_scene.hpp"
#include "eval/virtual_protocol.hpp"
#include "fit/monocular_prior.hpp"
#include "posedb/database.hpp"

namespace mocap::eval {

enum class MultiviewMethod {
  pose2sim_rule,
  per_frame,
  tracking,
  skeleton_fit,
  skeleton_fit_live,
  skeleton_fit_prior  // full, + the monocular retrieval's prior (fit::MonocularPrior)
};
std::string_view method_label(MultiviewMethod method);
bool fits_skeleton(MultiviewMethod method);  // skeleton_fit, skeleton_fit_live or _prior

struct MultiviewCase {
  int views = 4;
  int people = 3;
  float noise = 0.02f;  // σ as a fraction of the box height
};

struct MultiviewProtocolOptions {
  int frames = 300;  // frame sets per case (10 s at 30 fps)
  double fps = 30.0;
  float dropout = 0.10f;
  float outliers = 0.05f;
  float false_detections = 0.2f;  // chance per view and frame
  bool occlusion = true;
  // CPU seconds at most per method and case: Pose2Sim's rule tries subsets of cameras and can
  // take seconds per frame set at 16 views; the frames it got through are reported.
  double budget_s = 60.0;
  std::uint64_t seed = 1;
  // A pose database (the CMU train split): adds (iv) + skeleton fit + monocular prior, full mode,
  // the prior retrieved from it with fit::MonocularPrior's defaults.
  const posedb::Database* prior_db = nullptr;
  fit::MonocularPriorOptions prior;  // its settings (defaults: as chosen on train data)
};

struct MultiviewResult {
  MultiviewCase scene;
  MultiviewMethod method = MultiviewMethod::tracking;
  long frames = 0;  // frame sets evaluated
  SceneScore score;
  double pa_mpjpe_mm = 0.0;        // per person-frame similarity alignment, mean over joints
  double accel_error_mm = 0.0;     // mm/frame², joints reconstructed in three consecutive frames
  double bone_std_mm = 0.0;        // std of each of the 14 bones' length per person, mean
  double truth_bone_std_mm = 0.0;  // the same of the truth in the frames scored (rigid: ~0)
  double cpu_s = 0.0;              // reconstruction (+ fit for (iv))
  double wrong_association_share() const {
    return score.person_frames > 0
               ? static_cast<double>(score.wrong_associations) / score.person_frames
               : 0.0;
  }
};

// The held-out clips of a cmu31 folder (splits.txt), at `fps`. Throws InputError naming the folder.
std::vector<TruthSequence> load_heldout_clips(const std::string& cmu_folder, double fps);

// Renders the case once and runs every method on it.
std::vector<MultiviewResult> run_multiview_case(const std::vector<TruthSequence>& clips,
                                                const MultiviewCase& scene,
                                                const MultiviewProtocolOptions& options);

// Markdown table of results (one row per case and method).
std::string multiview_table(const std::vector<MultiviewResult>& results);

// Metrics over time from a scorer that kept its tracks (SceneScorer keep_tracks).
void add_track_metrics(const std::vector<ScenePersonTrack>& tracks, MultiviewResult& out);

}  // namespace mocap::eval
