#pragma once
// Issue 19 report 1: our multi-view reconstruction of Pose2Sim's demo (../shared/data/eval/
// pose2sim_demo: 4 calibrated views, OpenPose BODY_25B JSON) against Pose2Sim's own triangulated
// TRC of the same JSON and calibration, marker by marker (the TRC's markers are BODY_25B
// keypoints of the same names; Neck is keypoint 17, Head 18).
//
// Four reconstructions in one run, each MultiViewReconstructor over the BODY_25B keypoints,
// undistorted with each camera's lens: ours (association, robust triangulation, tracking with its
// prior), ours without the tracks' prior (per-frame geometry), our implementation of Pose2Sim's
// rule (confidence-weighted DLT, views dropped until the mean reprojection error is under 15 px),
// and ours + the skeleton fit on all views (full mode per track, fit::fit_tracks with
// multiview_fit_defaults(), the rig's floor), compared on the markers that are body joints.
// The participant in each frame is the person whose mid-hip is nearest the TRC's (within 0.5 m).
//
// Reprojection errors, pixels, per marker: "used" is the triangulator's mean over the views it
// kept; "all" projects a 3D point (ours, or the TRC's marker) through each camera (with its lens)
// onto the participant's detections of confidence >= 0.3 (Pose2Sim's likelihood threshold) and
// averages over them, the same footing for both.

#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "core/messages.hpp"
#include "io/openpose_json.hpp"
#include "io/trc.hpp"
#include "multiview/reconstructor.hpp"

namespace mocap::eval {

// The demo as read: the calibration's cameras, each camera's BODY_25B JSON, the raw TRC.
struct Pose2SimDemo {
  std::string trial, calibration;  // the paths read
  std::vector<camera::Camera> cameras;
  GroundPlane floor;  // the rig's (Pose2Sim's world: z = 0)
  std::vector<multiview::ViewGeometry> views;
  std::vector<io::OpenPoseSequence> json;  // per camera, in folder name order
  io::TrcFile trc;
  std::size_t frames = 0;  // compared: the TRC's, at most max_frames

  // Frame i's detections, undistorted with each camera's lens.
  void observations(std::size_t i, multiview::FrameObservations& out) const;
  // Whether camera c's detection d (-1: none) has keypoint k at Pose2Sim's likelihood threshold.
  bool confident(std::size_t i, std::size_t c, int d, int k) const;
  // Distance of `world`'s projection through camera c to keypoint k of its detection d (raw
  // pixels, so through the lens); NaN when it is not confident or does not project.
  float error_px(std::size_t i, std::size_t c, int d, int k, const glm::dvec3& world) const;
  // Mean distance of `world`'s projection to keypoint k of the participant's confident
  // detections (raw pixels, so through the lens); NaN without one.
  float error_all_px(std::size_t i, std::span<const int> detections, int k,
                     const glm::dvec3& world) const;
};

// Reads `trial` (pose/camXX_json in name order = the calibration's cameras; the raw
// pose-3d/*_0-*.trc, not the filtered one), at most `max_frames` frames (0: all). Throws
// InputError naming a file that cannot be read.
Pose2SimDemo load_pose2sim_demo(const std::filesystem::path& trial,
                                const std::filesystem::path& calibration,
                                std::size_t max_frames = 0);

struct Pose2SimMarkerStats {
  std::vector<float> distance_m;        // ours − TRC per frame
  std::vector<float> views;             // views used per frame
  std::vector<float> error_used_px;     // triangulator's error on the views used
  std::vector<float> error_all_px;      // ours projected onto every confident detection
  std::vector<float> trc_error_all_px;  // the TRC's marker, the same way (same frames)
  // Per camera: frames in which its detection has the keypoint with confidence >= 0.3 but the
  // point was not triangulated from it (the views a rule left out; empty for the fit).
  std::vector<int> left_out;
  std::vector<float> left_out_error_px;  // the point projected onto each keypoint left out
  // The fit only: distance of the fitted joint to the triangulated keypoint it was fitted from
  // (the same person and frame before the fit): how far the fit itself moves the point.
  std::vector<float> from_triangulated_m;
};

struct Pose2SimRun {
  std::string name;
  bool fitted = false;                           // the skeleton fit's joints, not a triangulation
  std::vector<Pose2SimMarkerStats> markers;      // TRC marker order
  std::vector<std::vector<float>> limb_lengths;  // per limb (pose2sim_limbs()), metres
  std::vector<float> hip_width_m;                // RHip to LHip per frame
  int frames_with_participant = 0;
  int other_people = 0;
  int outside_people = 0;
};

// Every marker's stats of a run together.
Pose2SimMarkerStats pooled(const Pose2SimRun& run);

struct Pose2SimComparison {
  std::string trial, calibration, reference;
  std::size_t frames = 0;
  std::vector<std::string> markers;
  std::vector<std::string> cameras;  // the rig's names, in its order
  std::vector<std::vector<float>> trc_limb_lengths;
  std::vector<float> trc_hip_width_m;
  std::vector<Pose2SimRun> runs;  // ours, without the prior, Pose2Sim's rule, + skeleton fit
};

// The eight limbs between TRC markers whose length std is reported.
const std::vector<std::pair<std::string, std::string>>& pose2sim_limbs();

// Called for each frame of a run once its participant is known: the frame, the reconstruction's
// result, the participant's index in it (-1: none).
using Pose2SimFrameObserver =
    std::function<void(std::size_t frame, const multiview::FrameResult&, int participant)>;

// One reconstruction of the demo with `options` (`fit`: + the skeleton fit on all views, full
// mode, over the tracks, compared on the markers that are body joints).
Pose2SimRun run_pose2sim_demo(const Pose2SimDemo& demo, std::string name,
                              const multiview::ReconstructionOptions& options, bool fit = false,
                              const Pose2SimFrameObserver& observe = {});

// The comparison's trial, reference, markers and the TRC's limb lengths, without runs.
Pose2SimComparison pose2sim_comparison(const Pose2SimDemo& demo);

// load_pose2sim_demo, then the four reconstructions.
Pose2SimComparison compare_with_pose2sim(const std::filesystem::path& trial,
                                         const std::filesystem::path& calibration,
                                         std::size_t max_frames = 0);

// Markdown: the per-marker table, the limb-length std line, the hip width and the views each
// triangulation left out per marker and camera.
std::string pose2sim_table(const Pose2SimComparison& c);

float median_of(std::vector<float> v);  // NaN when empty
float mean_of(const std::vector<float>& v);
float limb_std_m(const std::vector<std::vector<float>>& lengths);  // mean over limbs

}  // namespace mocap::eval
