#pragma once
// Triangulation of keypoints seen by several calibrated views (undistorted pixels), two ways:
//
// - ours (`triangulate_robust`): confidence-weighted least squares in metres: each view's two
//   DLT rows are divided by its focal length, so that a row's residual is the pixel error times
//   depth / focal, the distance in metres at the point between the ray and the point. Under the
//   usual noise model (pixel noise proportional to the person's size in the image) these residuals
//   have one scale in every view, so least squares on them is the maximum-likelihood estimate and
//   one threshold in metres fits near and far cameras. All views are kept when each one agrees
//   with the point triangulated from the others (its held-out residual is within the threshold:
//   an outlier's share of an all-view fit would hide part of its error). Outlier views (left/right
//   swaps, jumps, another person's keypoint) are found without trying every subset: up to
//   `pair_search_views` views, every pair of views proposes a point and the one most views agree
//   with wins (at most 15 pairs); above that, the worst view is dropped while any residual exceeds
//   the threshold (least squares over many views is dominated by the inliers, so the worst view is
//   an outlier), and dropped views that agree with the final point come back.
// - the baseline (`triangulate_pose2sim`): Pose2Sim's rule (Pose2Sim/triangulation.py,
//   `triangulation_from_best_cameras`, and common.py `weighted_triangulation`, at the commit of
//   ../shared/data/eval/pose2sim_demo, handle_LR_swap and undistort_points off as in its
//   Config.toml): views below the likelihood threshold (0.3) are left out; the homogeneous DLT
//   with each view's rows multiplied by its likelihood, solved by SVD; if the mean reprojection
//   error (pixels, unweighted) is above 15 px, every subset with one view less is tried and the
//   one with the smallest error kept, then two views less, ..., down to 2 views; still above the
//   threshold: no point. At 16 views this is up to 2^16 subsets per keypoint.
//
// Both keep, per point, the views used and the mean reprojection error over them.

#include <bit>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "multiview/view_geometry.hpp"

namespace mocap::multiview {

struct TriangulatedPoint {
  glm::vec3 position{std::numeric_limits<float>::quiet_NaN()};  // world, metres; NaN: none
  std::uint64_t views = 0;                                      // bit v set: view v was used
  float error_px = std::numeric_limits<float>::quiet_NaN();     // mean reprojection error, pixels
  float error_m = std::numeric_limits<float>::quiet_NaN();      // the same as metres at the point

  bool valid() const { return views != 0; }
  int view_count() const { return std::popcount(views); }
};

// One view's sighting of a point.
struct PointObservation {
  int view = 0;          // index into the views
  float x = 0, y = 0;    // undistorted pixels
  float confidence = 0;  // weight; <= 0 or a non-finite coordinate: not seen
};

struct RobustRule {
  // Observations at or below this confidence are left out.
  float min_confidence = 0.0f;
  // A view whose residual at the point exceeds this many metres is an outlier. The person-level
  // triangulation raises it with the noise it measures (TriangulationOptions): this is the floor
  // for clean input (0.05 m: on the virtual scenes of CMU train clips, 0.03 / 0.05 / 0.1 m gave
  // 2.6 / 3.8 / 6.6 mm MPJPE at σ 0 and the same within 1 mm at σ 1–5 %).
  float outlier_m = 0.05f;
  // Up to this many views the consensus of all view pairs is searched; above, the worst view is
  // dropped while a residual is above the threshold.
  int pair_search_views = 6;
};

struct Pose2SimRule {
  float likelihood_threshold = 0.3f;  // likelihood_threshold_triangulation
  float reprojection_px = 15.0f;      // reproj_error_threshold_triangulation
  int min_views = 2;                  // min_cameras_for_triangulation
};

// Confidence-weighted least squares in metres over every usable observation; nullopt with fewer
// than two views or rays too close to parallel.
std::optional<glm::dvec3> triangulate_least_squares(std::span<const ViewGeometry> views,
                                                    std::span<const PointObservation> seen);
// Pose2Sim's weighted DLT (homogeneous, smallest singular vector) over every given observation;
// nullopt with fewer than two views or a point at infinity.
std::optional<glm::dvec3> triangulate_dlt(std::span<const ViewGeometry> views,
                                          std::span<const PointObservation> seen);

// Where a track expects the point, as one more measurement of it: `weight` is its information
// relative to one view's rows (the view noise variance over the prediction's, times the views'
// squared confidence).
struct PointPrior {
  glm::dvec3 point{0.0};
  double weight = 0.0;
};

// With a prior, the views are chosen as without it and the point then fused with the prior (a
// Kalman update in information form: near-parallel rays leave the depth to the prediction), and
// one view that agrees with the prediction within the threshold is enough. `innovation_m` gets
// the distance between the views' own point and the prior's when three views or more fix it
// (NaN otherwise): how well the track predicts.
TriangulatedPoint triangulate_robust(std::span<const ViewGeometry> views,
                                     std::span<const PointObservation> seen,
                                     const RobustRule& rule = {}, const PointPrior* prior = nullptr,
                                     float* innovation_m = nullptr);
TriangulatedPoint triangulate_pose2sim(std::span<const ViewGeometry> views,
                                       std::span<const PointObservation> seen,
                                       const Pose2SimRule& rule = {});

// For the noise estimate of a person (person_triangulation.hpp): triangulates robustly and, when
// three views or more are kept, appends each kept view's metric residual at the point
// triangulated from the other kept views; with two views kept, the gap between their rays (the
// closest a held-out residual comes with one other view) to `two_view_gaps`.
void held_out_residuals(std::span<const ViewGeometry> views, std::span<const PointObservation> seen,
                        const RobustRule& rule, std::vector<float>& out,
                        std::vector<float>& two_view_gaps);

// Per observation of `seen` (out[i] for seen[i]), its metric residual at the point triangulated
// from the other views `point` was made from: how well a view agrees with the rest without
// pulling the point towards itself. With fewer than two other views, the residual at `point`.
// NaN for unusable observations or an invalid point.
void observation_residuals(std::span<const ViewGeometry> views,
                           std::span<const PointObservation> seen, const TriangulatedPoint& point,
                           std::span<float> out);

// Pixel and metric residual of one observation at a point; +inf behind the camera.
struct Residual {
  double px = 0.0;
  double m = 0.0;
};
Residual residual(const ViewGeometry& view, const PointObservation& seen, const glm::dvec3& point);

}  // namespace mocap::multiview
