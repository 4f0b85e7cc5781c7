#pragma once
// Why a camera is far worse than the rest (view_errors.hpp), for two user mistakes that every
// earlier check lets through (issues 19/20):
// - two views given in each other's place (`VIEW2 VIEW3` for `VIEW3 VIEW2`): only between
//   cameras of one image size, since other sizes are refused earlier;
// - a view's keypoints made at another image size than its camera's (OpenPose run on a resized
//   video): its keypoints are the right ones times a factor, about the image origin.
// Each explanation is tried on every view and pair of views up to 6 cameras (an exchange among few
// cameras spoils every camera's check alike, since the others' triangulation holds the wrong
// view: on Pose2Sim's demo nobody is flagged, all read 90-360 px), on the flagged ones beyond
// (pairs with a flagged camera, not permutations); a view's factor is fitted to where the other
// cameras put its joints. Round by round the one that leaves the lowest mean error is applied.
// It is said only when, applied, each camera it touches has its median error lowered by the flag
// rule's own ratio (2x) and so has the rig's mean error (a partial explanation that leaves the
// others as bad does not count), no camera losing its points. A camera may stay flagged (its
// calibration may be off too: it is then named as unexplained). On a right rig an exchange or a
// scale makes the cameras it touches worse, never twice better.
//
// The thresholds are set a priori, not on the test data: ViewErrorOptions' own flag ratio, the
// ratio that flags a camera; a factor is reported only when it differs from 1 by more than 5 % (a
// resized video differs by 25 % or more: 1440, 1280, 960 or 720 px wide for 1920; below 5 % a
// scale is as well a focal length slightly off, which the camera's calibration, not its view,
// explains) and lies within 1/5..5 (4K keypoints for a 720p camera are 3x; beyond is a fit gone
// wrong).

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "multiview/view_errors.hpp"

namespace mocap::multiview {

struct ViewCheckOptions {
  ViewErrorOptions errors;
  double min_scale_change = 0.05;  // |factor - 1| above which a scale is an explanation
  // The first frames in which every view shows somebody are used, at most this many: enough for
  // medians over hundreds of joints per camera, and a bounded time (~0.1 s per evaluation).
  std::size_t max_frames = 60;
};

struct ExchangedViews {
  std::size_t first = 0, second = 0;  // the two views, in the order given
  double before_px[2] = {0, 0};       // their median errors as given
  double after_px[2] = {0, 0};        // and exchanged
};

struct ScaledView {
  std::size_t view = 0;
  double factor = 1;  // the view's keypoints times this land where the other cameras put them
  double before_px = 0, after_px = 0;
  int image_width = 0, image_height = 0;  // the image size the keypoints look made at
};

struct ViewCheck {
  ViewErrorReport errors;            // as given
  ViewErrorReport explained_errors;  // with the explanations found applied
  std::vector<ExchangedViews> exchanged;
  std::vector<ScaledView> scaled;
  std::vector<std::size_t> unexplained;  // flagged views that no explanation fits
  bool explained() const { return !exchanged.empty() || !scaled.empty(); }
};

// `views[v]` are camera v's frames (distorted pixels as read), as for view_errors.
ViewCheck check_views(std::span<const camera::Camera> cameras,
                      std::span<const camera::BodySequence> views,
                      const ViewCheckOptions& options = {});

// One sentence per finding, naming each view by `labels[v]` (e.g. "view 2 (cam_02)"): the views
// that look exchanged or made at another size, with their errors before and after, and the
// flagged views left unexplained. Empty when nothing is flagged.
std::vector<std::string> describe(const ViewCheck& check, std::span<const camera::Camera> cameras,
                                  std::span<const std::string> labels);

}  // namespace mocap::multiview
