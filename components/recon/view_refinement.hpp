#pragma once
// The database's views are a grid (yaw steps of 12°, four camera heights): the matched view can be
// up to 6° off in yaw and more in elevation, and every joint away from the root moves with that
// error. Refinement searches yaw and elevation continuously around the matched view for the
// projection of the matched 3D body that best fits the person's normalised 2D pose.

#include <array>

#include <glm/vec3.hpp>

#include "core/body15.hpp"
#include "posedb/normalization.hpp"
#include "posedb/view_set.hpp"

namespace mocap::recon {

struct ViewRefinementOptions {
  float yaw_range_deg = 9.0f;  // searched on each side of the matched view
  float elevation_range_deg = 12.0f;
  int steps = 7;  // grid points per side and axis in the coarse pass
};

// `body`: root-relative joints facing +Z (the database frame), metres. `query`: the normalised 2D
// pose (NaN = missing joint). Returns the view (same distance) whose projection fits best.
posedb::View refine_view(const std::array<glm::vec3, kBodyJoints>& body,
                         const posedb::PoseVector& query, const posedb::View& matched,
                         float root_height_m, posedb::Scaling scaling,
                         const ViewRefinementOptions& options = {});

}  // namespace mocap::recon
