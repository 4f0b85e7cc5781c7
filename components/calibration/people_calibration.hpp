#pragma once
// Calibrating a rig's extrinsics from the people in view (`mocap calibrate rig --from-people`,
// issue 20 "Calibration from people", docs/cameras.md "Calibrating a rig from people"):
//
//   1. per view and frame one person (15 body joints): the detection with the most confident
//      joints times its height; once a first rig exists, the one that agrees with the other views
//      (reprojection of the point triangulated from them);
//   2. the best-connected pair of cameras from the essential matrix of their shared keypoints
//      (RANSAC), the other cameras one by one by PnP against the joints triangulated so far (most
//      shared keypoints first: a spanning tree grown from that pair);
//   3. one bundle adjustment (camera/rig_calibration.hpp's, Ceres) over the camera poses and the
//      3D joints of every frame used, with each bone's length shared by all frames and a robust
//      loss; observations whose error exceeds outlier_factor x the median are dropped and the
//      solve repeated;
//   4. metres from the bones: the person's standing height (given, else the canonical body's)
//      over motion::kStatureOverJointSpan x the head + trunk + thigh + shin bones; the floor from
//      the feet (fit::GroundEstimator), origin under the people's mean root, z up, x along the
//      first camera's heading.
//
// A library of its own (not components/camera): it needs the triangulation of components/multiview
// and the ground estimation of components/fit, which both build on components/camera.

#include <span>
#include <string>
#include <vector>

#include "camera/frame_offsets.hpp"
#include "camera/rig.hpp"

namespace mocap::calibration {

struct PeopleCalibrationOptions {
  double min_confidence = 0.3;  // keypoints below are not used (Pose2Sim's threshold)
  int min_joints = 8;           // a detection with fewer confident joints is not used
  int min_shared_frames = 20;   // frames with a person a camera must share with another camera
  // The person must move: the median joint's spread (RMS distance from its mean position over the
  // frames) in body heights, median over the views. Below: refused as standing still (the joints
  // of one pose are too few and too flat to fix the cameras).
  double min_motion = 0.05;
  int max_frames = 200;  // frames in the bundle adjustment, evenly spread over those usable
  // The person's standing height in metres (floor to top of head); 0: the canonical body's
  // (motion::canonical_stature_m()).
  double height_m = 0.0;
  double outlier_factor = 3.0;  // drop observations with error > factor x median, re-solve
  int outlier_rounds = 3;
  double outlier_floor_px = 2.0;  // never drop below this error (detector keypoints are noisy)
  double loss_px = 3.0;           // Huber loss scale of the reprojection errors
  double bone_weight_px_per_m = 200.0;  // a bone 1 cm off its length costs like 2 px
  int association_rounds = 2;  // several people: associate across the views and solve, repeated
};

struct PeopleCameraReport {
  std::string name;
  int frames = 0;        // frames in which the person was used in this view
  int observations = 0;  // keypoints in the final solve
  int dropped = 0;       // keypoints dropped as outliers
  double rms_px = 0.0;   // RMS reprojection error over the keypoints used
};

struct PeopleCalibration {
  camera::Rig rig;                          // cameras in view order, world and floor
  std::vector<PeopleCameraReport> cameras;  // the same order
  int frames_used = 0;                      // frames in the bundle adjustment
  double rms_px = 0.0;                      // over all keypoints used
  double height_m = 0.0;                    // the height that set the scale
  double motion = 0.0;                      // the measured motion (see min_motion)
  std::vector<std::string> notes;           // what a user should know
};

// Extrinsics of `cameras` (their intrinsics and names are kept, their poses ignored) from their
// views' people: views[k] is camera k's sequence, all of one length, frame i of each taken at the
// same instant; sources[k] names the view in messages. Throws InputError naming the view or
// camera when: the views differ in length, a view has no person, a camera shares fewer than
// min_shared_frames frames with the others, two views see the people at the same pixels (no
// baseline), the person hardly moves, or a camera cannot be placed.
PeopleCalibration calibrate_rig_from_people(std::span<const camera::Camera> cameras,
                                            std::span<const camera::BodySequence> views,
                                            std::span<const std::string> sources,
                                            const PeopleCalibrationOptions& options = {});

}  // namespace mocap::calibration
