#pragma once
// A person seen by several views, triangulated keypoint by keypoint (triangulation.hpp), and how
// well each view's detection agrees with the result: the association uses that to throw out a
// detection of somebody else.

#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "multiview/triangulation.hpp"

namespace mocap::multiview {

enum class TriangulationMethod { robust, pose2sim };

struct TriangulationOptions {
  TriangulationMethod method = TriangulationMethod::robust;
  RobustRule robust;
  Pose2SimRule pose2sim;
  // The robust outlier threshold of a person follows the 2D noise, which differs between
  // detectors, image sizes and people: every keypoint seen by three views or more is first
  // triangulated with the threshold at noise_ceiling_m (which keeps out another person's keypoints
  // and large jumps, and keeps the noise of a poor detector), and the person's threshold becomes
  // noise_factor × the median held-out residual of the views kept (triangulation.hpp), within
  // [robust.outlier_m, noise_ceiling_m]. 3 × the median length of a 2D Gaussian residual is
  // about 3.5 σ: 0.2 % of the inliers are lost.
  float noise_factor = 3.0f;
  float noise_ceiling_m = 0.3f;
};

// One view's detection of the person: its keypoints as count × (x, y, confidence), undistorted.
struct Sighting {
  int view = 0;
  std::span<const float> xyc;
};

// Where a track expects a keypoint: a point and the standard deviation of that expectation per
// axis (metres). NaN point: no expectation.
struct KeypointPrior {
  glm::vec3 point{std::numeric_limits<float>::quiet_NaN()};
  float sigma_m = 0.0f;
};

// Reuses its buffers: nothing is allocated per frame once the largest person has been seen.
class PersonTriangulator {
 public:
  // Triangulates the out.size() keypoints of a person from its sightings (one per view). Per
  // sighting, `sighting_residual_m` gets the median over its keypoints of the residual at the
  // point triangulated from the other sightings (triangulation.hpp, observation_residuals; NaN
  // when none compares): a detection of somebody else stands out even where it pulls the
  // all-view point towards itself. Returns the outlier threshold
  // used (metres; NaN for the Pose2Sim rule).
  //
  // With `priors` (one per keypoint, robust method only), each keypoint is fused with its prior
  // (triangulation.hpp, PointPrior), weighted by the person's measured view noise over the
  // prior's sigma, and `innovations` (one per keypoint) gets how far the views' own point was
  // from the prior.
  float triangulate(std::span<const ViewGeometry> views, std::span<const Sighting> sightings,
                    const TriangulationOptions& options, std::span<TriangulatedPoint> out,
                    std::span<float> sighting_residual_m,
                    std::span<const KeypointPrior> priors = {}, std::span<float> innovations = {});

 private:
  float noise_threshold(std::span<const ViewGeometry> views, std::span<const Sighting> sightings,
                        int keypoints, const TriangulationOptions& options);
  void gather(std::span<const Sighting> sightings, int keypoint);

  std::vector<PointObservation> seen_;
  std::vector<float> residuals_;
  std::vector<float> table_;  // keypoints × sightings
  std::vector<float> gaps_;
  float noise_m_ = 0.0f;  // median held-out residual of the person being triangulated
};

}  // namespace mocap::multiview
