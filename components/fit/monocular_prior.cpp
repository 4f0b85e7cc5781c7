#include "fit/monocular_prior.hpp"

#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "recon/sequence_reconstruction.hpp"

namespace mocap::fit {

namespace {

constexpr int kRoot = index(Joint::root);

// How well the views fix a point, worst first.
enum class Support { few = 0, two = 1, many = 2 };

// The sine of the largest angle between the rays of the views used for `point`.
double largest_ray_sine(const multiview::TriangulatedPoint& point,
                        std::span<const camera::Camera> cameras) {
  const glm::dvec3 p(point.position);
  double best = 0.0;
  for (std::size_t a = 0; a < cameras.size() && a < 64; ++a) {
    if (!(point.views >> a & 1u)) continue;
    const glm::dvec3 ra = glm::normalize(p - cameras[a].centre());
    for (std::size_t b = a + 1; b < cameras.size() && b < 64; ++b) {
      if (!(point.views >> b & 1u)) continue;
      const glm::dvec3 rb = glm::normalize(p - cameras[b].centre());
      best = std::max(best, glm::length(glm::cross(ra, rb)));
    }
  }
  return best;
}

Support support(const multiview::TriangulatedPoint& point, std::span<const camera::Camera> cameras,
                const MonocularPriorOptions& options) {
  if (!point.valid() || point.view_count() < 2) return Support::few;
  // The depth's uncertainty: the 2D noise at the point magnified by nearly parallel rays.
  const double sine = std::max(largest_ray_sine(point, cameras), 1e-3);
  if (!(point.error_m / sine <= options.max_depth_error_m)) return Support::few;  // NaN: few
  return point.view_count() >= 3 ? Support::many : Support::two;
}

// How well a view sees the person: joints present, then the larger side of their box.
std::pair<int, double> sight(const recon::BodyXyc& k, double min_confidence) {
  int n = 0;
  float x0 = std::numeric_limits<float>::max(), x1 = -x0, y0 = x0, y1 = -x0;
  for (int j = 0; j < kBodyJoints; ++j) {
    const float x = k[3 * j], y = k[3 * j + 1];
    if (!(k[3 * j + 2] >= min_confidence) || !std::isfinite(x) || !std::isfinite(y)) continue;
    ++n;
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  return {n, n >= 2 ? std::max(x1 - x0, y1 - y0) : 0.0};
}

}  // namespace

MonocularPrior::MonocularPrior(const posedb::Database& db, MonocularPriorOptions options)
    : db_(db), options_(options), matcher_(db, options.match) {
  candidates_.reserve(static_cast<std::size_t>(std::max(1, options.match.k)));
}

double MonocularPrior::bone_weight(const multiview::TriangulatedPoint& parent,
                                   const multiview::TriangulatedPoint& child,
                                   std::span<const camera::Camera> cameras) const {
  const Support s = std::min(support(parent, cameras, options_), support(child, cameras, options_));
  const double sigma = s == Support::few   ? options_.few_views_rad
                       : s == Support::two ? options_.two_views_rad
                                           : options_.many_views_rad;
  return sigma > 0.0 ? 1.0 / sigma : 0.0;
}

bool MonocularPrior::add(MultiViewFrameInput& frame,
                         std::span<const multiview::TriangulatedPoint> body,
                         std::span<const camera::Camera> cameras) {
  frame.prior = {};
  // The view that sees the person best, among those whose camera can turn a pose onto its ray.
  const ViewKeypoints* best = nullptr;
  std::pair<int, double> best_sight{0, 0.0};
  for (const ViewKeypoints& v : frame.views) {
    if (v.camera < 0 || static_cast<std::size_t>(v.camera) >= cameras.size() ||
        !cameras[static_cast<std::size_t>(v.camera)].has_intrinsics())
      continue;
    const auto s = sight(v.keypoints, options_.match.scaler.min_confidence);
    if (s > best_sight) best = &v, best_sight = s;
  }
  if (best == nullptr || body.size() < static_cast<std::size_t>(kBodyJoints)) return false;
  if (!matcher_.match(best->keypoints, candidates_) || candidates_.empty()) return false;

  const camera::Camera& cam = cameras[static_cast<std::size_t>(best->camera)];
  recon::Pose3D pose = recon::pose_in_camera(db_, candidates_.front());
  const float root_confidence = best->keypoints[3 * kRoot + 2];
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const glm::vec2 root_pixel =
      root_confidence > 0.0f ? glm::vec2(best->keypoints[3 * kRoot], best->keypoints[3 * kRoot + 1])
                             : glm::vec2(nan, nan);
  recon::turn_onto_ray(pose, cam, root_pixel);
  frame.prior.robust_rad = static_cast<float>(std::max(0.0, options_.robust_rad));
  const glm::dmat3 camera_to_world = glm::transpose(cam.rotation);
  for (int b = 0; b < kBodyJoints - 1; ++b) {
    const int parent = kJointParent[static_cast<std::size_t>(b)];
    const glm::dvec3 bone = glm::dvec3(pose.joints[static_cast<std::size_t>(b)]) -
                            glm::dvec3(pose.joints[static_cast<std::size_t>(parent)]);
    const double len = glm::length(bone);
    if (!(len > 1e-4) || !std::isfinite(len)) continue;
    frame.prior.direction[static_cast<std::size_t>(b)] = glm::vec3(camera_to_world * (bone / len));
    const double weight = bone_weight(body[static_cast<std::size_t>(parent)],
                                      body[static_cast<std::size_t>(b)], cameras);
    frame.prior.inv_sigma[static_cast<std::size_t>(b)] = static_cast<float>(weight);
    const bool few = options_.few_views_rad > 0.0 && weight >= 1.0 / options_.few_views_rad;
    frame.prior.few[static_cast<std::size_t>(b)] = few;
    frame.prior.reference[static_cast<std::size_t>(b)] = options_.few_views_reference && few;
  }
  return frame.prior.any();
}

namespace {

// Bone b lacked two good views at this frame: marked few, or no retrieval at all.
bool lacking(const DirectionPrior& p, int b) {
  const auto bone = static_cast<std::size_t>(b);
  return p.few[bone] || !(glm::length(p.direction[bone]) > 0.0f);
}

}  // namespace

float MonocularPrior::run_weight(std::size_t run) const {
  const double sigma = run >= static_cast<std::size_t>(std::max(1, options_.few_views_frames))
                           ? options_.few_views_rad
                           : options_.two_views_rad;
  return sigma > 0.0 ? static_cast<float>(1.0 / sigma) : 0.0f;
}

void MonocularPrior::settle_runs(std::span<MultiViewFrameInput> track, bool past_only) const {
  for (int b = 0; b < kBodyJoints - 1; ++b) {
    const auto bone = static_cast<std::size_t>(b);
    for (std::size_t start = 0; start < track.size();) {
      if (!lacking(track[start].prior, b)) {
        ++start;
        continue;
      }
      std::size_t end = start;  // the run is [start, end)
      while (end < track.size() && lacking(track[end].prior, b)) ++end;
      for (std::size_t f = start; f < end; ++f) {
        DirectionPrior& p = track[f].prior;
        if (!p.few[bone]) continue;
        p.inv_sigma[bone] = run_weight(past_only ? f + 1 - start : end - start);
        p.reference[bone] = options_.few_views_reference && p.inv_sigma[bone] > 0.0f &&
                            p.inv_sigma[bone] == run_weight(SIZE_MAX);
      }
      start = end;
    }
  }
}

void MonocularPrior::settle_newest(DirectionPrior* prior, Runs& run) const {
  for (int b = 0; b < kBodyJoints - 1; ++b) {
    const auto bone = static_cast<std::size_t>(b);
    run[bone] = !prior || lacking(*prior, b) ? std::min(run[bone], INT_MAX - 1) + 1 : 0;
    if (!prior || !prior->few[bone]) continue;
    prior->inv_sigma[bone] = run_weight(static_cast<std::size_t>(run[bone]));
    prior->reference[bone] = options_.few_views_reference && prior->inv_sigma[bone] > 0.0f &&
                             prior->inv_sigma[bone] == run_weight(SIZE_MAX);
  }
}

}  // namespace mocap::fit
