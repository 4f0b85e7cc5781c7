#pragma once
// Measuring where a 2D keypoint layout puts its joints relative to the canonical body's joint
// centres (docs/keypoint-layouts.md), from data that has both the layout's keypoints and
// anatomical joint centres in 3D, and fitting the coefficients of recon/layout_offsets.hpp.
//
// Sources:
// - Pose2Sim (../shared/data/eval/pose2sim_demo): the triangulated BODY_25B keypoints and the
//   LSTM anatomical markers of the *_LSTM.trc files. Reference joint centres: hips = RHJC/LHJC;
//   knees, ankles, elbows, wrists = midpoint of the lateral and medial markers; shoulders = the
//   acromion marker moved down the trunk by 17 % of the acromion-to-acromion distance (the
//   glenohumeral centre rule of Rab, Petuskey and Bagley, Gait & Posture 2002); neck and head as
//   the canonical body defines them: 23 mm and 223 mm above the shoulder-centre midpoint along
//   the trunk (hip-centre midpoint to shoulder-centre midpoint); root = hip-centre midpoint.
// - HumanEva-I 3D (its joints are model joint centres except thorax, pelvis and headDistal):
//   shoulders, hips and limbs are the reference themselves; neck, head and root are referred to
//   the shoulder and hip midpoints as above.

#include <array>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "camera/camera.hpp"
#include "core/body15.hpp"
#include "core/keypoint_layout.hpp"
#include "io/humaneva.hpp"
#include "io/trc.hpp"
#include "recon/layout_offsets.hpp"

namespace mocap::eval {

using Joints3 = std::array<glm::vec3, kBodyJoints>;  // NaN: not available

inline constexpr float kCanonicalNeckAboveShoulders = 0.023f;  // m, CMU cgspeed Neck1
inline constexpr float kCanonicalHeadAboveShoulders = 0.223f;  // m, CMU cgspeed head top
inline constexpr float kAcromionToShoulderCentre = 0.17f;      // of the biacromial distance

// One instant: the layout's keypoints as Body15 (as core::to_body15 makes them, in 3D) and the
// canonical joint centres of the same person.
struct CalibrationFrame {
  Joints3 keypoints;
  Joints3 reference;
};

// Frames from a Pose2Sim *_LSTM.trc file (its BODY_25B markers and its anatomical markers), with
// the keypoints as `layout` would place them: BODY_25B directly; COCO-17, BODY_25 and COCO-18
// from the BODY_25B keypoints they share (the same COCO annotations), their neck and mid-hip as
// midpoints; their head (ear midpoint) is not available (NaN: no ear markers in 3D).
std::vector<CalibrationFrame> pose2sim_frames(const io::TrcFile& lstm, LayoutId layout);

// Frames from HumanEva-I 3D (one split, every subject and action), layout HumanEva-15.
std::vector<CalibrationFrame> humaneva_frames(const io::humaneva::Dataset& data,
                                              io::humaneva::Split split);

// The basis each joint is fitted in: head, neck, shoulders -> shoulders; hips, root -> hips;
// elbows, wrists, knees, ankles -> bone. HumanEva-15: its shoulders, hips and limbs are joint
// centres already -> none.
std::array<recon::OffsetBasis, kBodyJoints> default_bases(LayoutId layout);

struct JointFit {
  int frames = 0;               // frames with the joint and its basis present
  double before_mm = 0.0;       // mean distance keypoint -> reference
  double after_mm = 0.0;        // mean distance corrected keypoint -> reference
  glm::dvec3 mean_offset_mm{};  // mean (reference - keypoint) in the body frame: up, left, forward
  double along_mm = 0.0;        // the fitted offset at the mean basis length: along * |T| or |bone|
  double lateral_mm = 0.0;      // lateral * |left - right|
  double forward_mm = 0.0;      // forward * |N|
  double after_3d_mm = 0.0;     // after, with the forward part too (3D only)
};

struct LayoutFit {
  recon::LayoutOffsets offsets;
  std::array<JointFit, kBodyJoints> joints{};
  std::string notes;  // one line per joint that could not be estimated, and why
};

// Least squares per joint: min over frames of |reference - keypoint - offset|^2 in 3D. In the
// result, after_mm is with the in-plane (2D-applicable) part only, after_3d_mm with `forward`.
LayoutFit fit_layout_offsets(LayoutId layout, std::span<const CalibrationFrame> frames,
                             const std::array<recon::OffsetBasis, kBodyJoints>& bases);

// Mean 3D distance to the reference per joint, before and after applying `offsets`.
std::array<JointFit, kBodyJoints> evaluate_offsets_3d(const recon::LayoutOffsets& offsets,
                                                      std::span<const CalibrationFrame> frames);

// The 2D check: keypoints and reference (TRC points, Y up; the calibration's world is Z up:
// X_w = Z_trc, Y_w = X_trc, Z_w = Y_trc) projected through each camera of a Pose2Sim calibration
// (camera/rig_file.hpp; pinhole projection), the 2D correction
// applied to the projected keypoints; mean distance before/after per joint, in millimetres at
// the joint's depth (pixels * depth / f).
std::array<JointFit, kBodyJoints> evaluate_offsets_2d(const recon::LayoutOffsets& offsets,
                                                      std::span<const CalibrationFrame> frames,
                                                      std::span<const camera::Camera> cameras);

}  // namespace mocap::eval
