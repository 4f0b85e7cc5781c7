#pragma once
// Frame offsets between the views of a calibrated rig filmed without a common clock (issue 20,
// "for files, a per-view frame offset, given or estimated from the keypoints' motion"). A view's
// offset is the one at which its keypoints lie on the epipolar lines of the reference view's
// keypoints: people moving across the lines make a wrong offset cost pixels. Unlike correlating
// vertical keypoint speeds (Pose2Sim's way), this needs no vertical motion and no similar
// viewpoints; it needs the rig. docs/cameras.md: the method and its measured accuracy.

#include <array>
#include <span>
#include <string>
#include <vector>

#include "core/body15.hpp"
#include "core/messages.hpp"

namespace mocap::camera {

struct Camera;

using BodyKeypoints = std::array<Keypoint2D, kBodyJoints>;
// One view: per frame, its people as the 15 body joints (pixels, confidence; 0: missing).
using BodySequence = std::vector<std::vector<BodyKeypoints>>;

// The frames' people through their layouts (core/keypoint_layout.hpp).
BodySequence body_sequence(std::span<const People2D> frames);

struct OffsetOptions {
  int max_offset_frames = 30;   // offsets searched in [-max, max]
  int min_overlap_frames = 20;  // frames with people in both views needed at every offset
  double min_confidence = 0.2;  // keypoints below are not used
  // The best offset must fit this much better than a typical one (1 - best / median cost), or
  // the people did not move enough across the epipolar lines to tell.
  double min_contrast = 0.3;
};

struct ViewOffset {
  // The view's frame i shows the instant of the reference view's frame i + frames (a view that
  // started late has a positive offset); with a fraction of a frame.
  double frames = 0.0;
  double contrast = 0.0;  // 1 - best / median cost over the offsets tried
  double cost = 0.0;      // at the best offset: mean epipolar distance in body heights
  bool found = false;
  std::string problem;  // why not found
};

// Per frame, each person of the view is paired with the reference person whose keypoints fit
// best; the cost of an offset is the mean over the frames of the trimmed mean symmetric epipolar
// distance of the pairs' joints, in the view's person heights. `cameras` are the views' cameras,
// in the same order; keypoints are undistorted here. The reference's own offset is 0.
std::vector<ViewOffset> estimate_offsets(std::span<const Camera> cameras,
                                         std::span<const BodySequence> views,
                                         std::size_t reference = 0,
                                         const OffsetOptions& options = {});

}  // namespace mocap::camera
