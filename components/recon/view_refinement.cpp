#include "recon/view_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/trigonometric.hpp>

#include "posedb/projection.hpp"

namespace mocap::recon {
namespace {

float fit_error(const std::array<glm::vec3, kBodyJoints>& body, const posedb::PoseVector& query,
                const posedb::View& view, float root_height_m, posedb::Scaling scaling) {
  std::array<glm::vec2, kBodyJoints> image;
  posedb::project_body(body, posedb::view_camera(view, root_height_m), image);
  posedb::PoseVector projected;
  if (!posedb::normalize_pose(image, scaling, projected)) return std::numeric_limits<float>::max();
  float error = 0.0f;
  for (int d = 0; d < posedb::kPoseDims; ++d) {
    if (std::isfinite(query[d])) error += (projected[d] - query[d]) * (projected[d] - query[d]);
  }
  return error;
}

posedb::View with_angles(const posedb::View& base, float yaw_deg, float elevation_deg,
                         float root_height_m) {
  posedb::View v = base;
  v.yaw_deg = yaw_deg;
  v.pitch_deg = elevation_deg;
  v.height_m = root_height_m + base.distance_m * std::tan(glm::radians(elevation_deg));
  return v;
}

}  // namespace

// Two grid passes (coarse, then around the best point at a third of the spacing): the error is
// smooth in both angles near the match, and 2 × (2 steps + 1)² projections cost microseconds.
posedb::View refine_view(const std::array<glm::vec3, kBodyJoints>& body,
                         const posedb::PoseVector& query, const posedb::View& matched,
                         float root_height_m, posedb::Scaling scaling,
                         const ViewRefinementOptions& options) {
  posedb::View best = matched;
  float best_error = fit_error(body, query, matched, root_height_m, scaling);
  float yaw = matched.yaw_deg, elevation = matched.pitch_deg;
  float yaw_step = options.yaw_range_deg / static_cast<float>(options.steps);
  float elevation_step = options.elevation_range_deg / static_cast<float>(options.steps);
  for (int pass = 0; pass < 2; ++pass) {
    const float centre_yaw = yaw, centre_elevation = elevation;
    for (int i = -options.steps; i <= options.steps; ++i) {
      for (int j = -options.steps; j <= options.steps; ++j) {
        const float e =
            std::clamp(centre_elevation + static_cast<float>(j) * elevation_step, -30.0f, 80.0f);
        const posedb::View v =
            with_angles(matched, centre_yaw + static_cast<float>(i) * yaw_step, e, root_height_m);
        const float error = fit_error(body, query, v, root_height_m, scaling);
        if (error < best_error) best_error = error, best = v, yaw = v.yaw_deg, elevation = e;
      }
    }
    yaw_step /= 3.0f;
    elevation_step /= 3.0f;
  }
  return best;
}

}  // namespace mocap::recon
