#pragma once
// A Pose2Sim trial (../shared/data/eval/pose2sim_demo/, see its README) as input for monocular
// evaluation with its true cameras: the calibration (a rig file, camera/rig_file.hpp), each
// camera's OpenPose BODY_25B JSON as Body15 keypoints, and Pose2Sim's own triangulated 3D (the
// *_filt_butterworth.trc file: its BODY_25B markers as Body15, root = mid-hip) as the reference,
// in the calibration's Z-up world frame. (The *_LSTM.trc file's copies of those markers are
// shifted: they reproject about twice as far from the detections.)
//
// The participant: a camera may see other people (cam01: a figure at the left border, cam02 one
// at x ≈ 800 px). In every frame and camera the detection whose Body15 keypoints lie closest to
// the reference projected through that camera (median pixel distance over the present joints) is
// taken; that distance is the reprojection check of the calibration reader.
//
// Frames: JSON index i is TRC Frame# i + 1 (the README's check); all cameras are synchronised.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "camera/camera.hpp"
#include "eval/virtual_protocol.hpp"
#include "recon/sequence_reconstruction.hpp"

namespace mocap::eval {

struct Pose2SimView {
  camera::Camera camera;
  std::string json_folder;
  std::vector<recon::BodyXyc> input;    // the participant per frame (confidence 0: none)
  std::vector<double> reprojection_px;  // per frame: median distance to the reference; NaN
  // The calibration check as the README makes it: the same detection, median over the TRC's 21
  // BODY_25B markers (feet and nose included) instead of the 15 body joints; NaN without one.
  std::vector<double> marker_reprojection_px;
  std::vector<int> people;         // detections per frame
  std::vector<Body> truth_camera;  // the reference in this camera's frame (x right, y down)
};

struct Pose2SimTrial {
  std::string folder;
  std::string reference_file;  // the TRC read
  double fps = 60.0;
  std::vector<Body> truth_world;  // Z-up world, metres
  std::vector<Pose2SimView> views;
};

// Reads `trial` (pose/camXX_json/, pose-3d/*_filt_butterworth.trc) with `calibration`: camera k of
// the calibration is the k-th camXX_json folder in name order. At most `max_frames` frames (0:
// all). Throws InputError for unreadable files or counts that do not match.
Pose2SimTrial load_pose2sim_trial(const std::filesystem::path& trial,
                                  const std::filesystem::path& calibration,
                                  std::size_t max_frames = 0);

// The trial's pose/camXX_json folders in name order, one per camera of `calibration` (which has
// `cameras`); throws InputError naming the folder when it cannot be listed or the counts differ.
std::vector<std::filesystem::path> pose2sim_json_folders(const std::filesystem::path& trial,
                                                         std::size_t cameras,
                                                         const std::filesystem::path& calibration);

// The BODY_25B keypoint a TRC marker is: the one of its name, but Neck = UpperNeck and Head =
// HeadTop (Pose2Sim's names); -1: none.
int pose2sim_marker_keypoint(std::string_view marker);

// The TRC point (Y up, OpenSim) in the calibration's Z-up world: (Z, X, Y).
glm::dvec3 trc_to_world(const glm::vec3& trc);

// Keypoints resampled from `from_fps` to `to_fps` by linear interpolation; a joint missing in
// either neighbouring frame is missing unless the output falls on the frame that has it.
std::vector<recon::BodyXyc> resample_keypoints(const std::vector<recon::BodyXyc>& frames,
                                               double from_fps, double to_fps);

// Bodies resampled the same way (motion::resample_points).
std::vector<Body> resample_bodies(const std::vector<Body>& frames, double from_fps, double to_fps);

}  // namespace mocap::eval
