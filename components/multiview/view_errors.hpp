#pragma once
// How well each camera of a rig agrees with the others, from keypoints (issue 19's "a camera
// whose calibration is off", issue 20's `mocap rig info RIG VIEW...`): every joint seen by the
// camera is triangulated from the *other* cameras alone (triangulate_robust: their consensus,
// one of them far off left out) and reprojected into it; the distance to its own keypoint is its
// error. A camera whose pose or intrinsics are off lands its keypoints
// far from where the others put the joint, while the others, triangulated without it, stay
// consistent. The check is done with one person walking through the space: per view and frame
// the tallest person (the span of its confident keypoints) is taken as that person, so that no
// association is needed (bystanders further away, partial detections are left out); frames in
// which a view shows nobody are skipped.

#include <span>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "camera/frame_offsets.hpp"

#include <glm/vec2.hpp>

namespace mocap::multiview {

struct ViewErrorOptions {
  double min_confidence = 0.3;  // keypoints below are not used (Pose2Sim's likelihood threshold)
  // A camera is flagged when its median error exceeds this many times the median of the other
  // cameras' medians (and min_flag_px): far worse than the rest.
  double flag_ratio = 2.0;
  double min_flag_px = 5.0;
};

struct ViewError {
  std::size_t points = 0;  // joints reprojected into this camera
  double median_px = 0, mean_px = 0;
  bool flagged = false;  // far worse than the rest (ViewErrorOptions)
};

struct ViewErrorReport {
  std::vector<ViewError> views;  // one per camera, in order
  std::size_t frames_used = 0;   // frames with a person in every view
  std::size_t frames = 0;        // frames in the shortest view
};

// The tallest person of a frame, by the vertical span of its confident keypoints (index -1:
// nobody), and that span.
struct TallestPerson {
  int index = -1;
  float height_px = 0;
};
TallestPerson tallest_person(const std::vector<camera::BodyKeypoints>& people,
                             double min_confidence);

// One joint seen by a camera: its keypoint as read (distorted pixels) and where the joint
// triangulated from the other cameras projects (undistorted pixels), with the keypoint undistorted.
struct ViewResidual {
  glm::dvec2 keypoint;     // as read
  glm::dvec2 undistorted;  // the keypoint, undistorted
  glm::dvec2 projected;    // the others' joint, undistorted
};

// Per camera its residuals (the data behind view_errors), and the frame counts.
struct ViewResiduals {
  std::vector<std::vector<ViewResidual>> views;
  std::size_t frames_used = 0, frames = 0;
};
ViewResiduals view_residuals(std::span<const camera::Camera> cameras,
                             std::span<const camera::BodySequence> views,
                             const ViewErrorOptions& options = {});

// `views[v]` are camera v's frames (body_sequence: 15 joints, distorted pixels as read).
ViewErrorReport view_errors(std::span<const camera::Camera> cameras,
                            std::span<const camera::BodySequence> views,
                            const ViewErrorOptions& options = {});

// The median of the other cameras' medians (those with points); NaN when there are none.
double others_median(const ViewErrorReport& report, std::size_t view);
// Sets each camera's `flagged` by the rule of ViewErrorOptions.
void flag_views(ViewErrorReport& report, const ViewErrorOptions& options);

}  // namespace mocap::multiview
