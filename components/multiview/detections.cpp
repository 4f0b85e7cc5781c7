#include "multiview/detections.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

namespace mocap::multiview {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Distance between two rays (origin, unit direction), capped; rays that come closest behind
// either origin cannot show one point in front of both cameras.
float ray_distance(const glm::vec3& ca, const glm::vec3& da, const glm::vec3& cb,
                   const glm::vec3& db, float cap) {
  const glm::vec3 baseline = cb - ca;
  const glm::vec3 normal = glm::cross(da, db);
  const float nn = glm::dot(normal, normal);
  if (nn < 1e-10f) {  // parallel: any depth fits, the lines' distance is all there is
    return std::min(glm::length(glm::cross(baseline, da)), cap);
  }
  const float ta = glm::dot(glm::cross(baseline, db), normal) / nn;
  const float tb = glm::dot(glm::cross(baseline, da), normal) / nn;
  if (ta <= 0.0f || tb <= 0.0f) return cap;
  return std::min(std::abs(glm::dot(baseline, normal)) / std::sqrt(nn), cap);
}

// Distance from a point to a ray (origin, unit direction), capped; a point behind the camera
// cannot be on the ray.
float point_ray_distance(const glm::vec3& point, const glm::vec3& origin, const glm::vec3& dir,
                         float cap) {
  const glm::vec3 v = point - origin;
  const float t = glm::dot(v, dir);
  if (t <= 0.0f) return cap;
  return std::min(std::sqrt(std::max(0.0f, glm::dot(v, v) - t * t)), cap);
}

}  // namespace

void DetectionTable::build(const FrameObservations& frame, std::span<const ViewGeometry> views,
                           const RayCostOptions& options) {
  if (static_cast<std::size_t>(frame.views()) != views.size()) {
    throw std::invalid_argument("DetectionTable: the frame has " + std::to_string(frame.views()) +
                                " views, the rig " + std::to_string(views.size()));
  }
  keypoints_ = frame.keypoints();
  terms_.resize(static_cast<std::size_t>(keypoints_));
  sparse_ = 0;
  detections_.clear();
  rays_.clear();
  confidence_.clear();
  centres_.clear();
  for (const ViewGeometry& v : views) centres_.push_back(glm::vec3(v.centre()));
  for (int view = 0; view < frame.views(); ++view) {
    for (int p = 0; p < frame.people(view); ++p) {
      const std::span<const float> xyc = frame.person(view, p);
      int usable = 0;
      for (int k = 0; k < keypoints_; ++k) {
        const float* kp = &xyc[static_cast<std::size_t>(k) * 3];
        usable += usable_keypoint(kp[0], kp[1], kp[2], options.min_confidence);
      }
      if (usable < options.min_keypoints) {
        ++sparse_;
        continue;
      }
      detections_.push_back({view, p, usable});
      for (int k = 0; k < keypoints_; ++k) {
        const float* kp = &xyc[static_cast<std::size_t>(k) * 3];
        const bool ok = usable_keypoint(kp[0], kp[1], kp[2], options.min_confidence);
        confidence_.push_back(ok ? kp[2] : 0.0f);
        rays_.push_back(ok ? glm::vec3(views[static_cast<std::size_t>(view)].ray(kp[0], kp[1]))
                           : glm::vec3(0.0f));
      }
    }
  }
}

float DetectionTable::trimmed_mean(int count, int min_common, float keep) const {
  if (count < min_common) return kNaN;
  const auto end = terms_.begin() + count;
  std::sort(terms_.begin(), end);
  float total = 0.0f;
  for (auto it = terms_.begin(); it != end; ++it) total += it->second;
  const float wanted = keep * total;
  float sum = 0.0f, weight = 0.0f;
  for (auto it = terms_.begin(); it != end && weight < wanted; ++it) {
    sum += it->first * it->second;
    weight += it->second;
  }
  return sum / weight;
}

float DetectionTable::pair_cost(int a, int b, const RayCostOptions& options) const {
  const glm::vec3& ca = centre((*this)[a].view);
  const glm::vec3& cb = centre((*this)[b].view);
  int count = 0;
  for (int k = 0; k < keypoints_; ++k) {
    const float w = confidence(a, k) * confidence(b, k);
    if (!(w > 0.0f)) continue;
    terms_[count++] = {ray_distance(ca, ray(a, k), cb, ray(b, k), options.cap_m), w};
  }
  return trimmed_mean(count, options.min_common, options.keep_pair);
}

float DetectionTable::point_cost(int i, std::span<const glm::vec3> points,
                                 const RayCostOptions& options) const {
  const glm::vec3& c = centre((*this)[i].view);
  int count = 0;
  for (int k = 0; k < keypoints_; ++k) {
    const float w = confidence(i, k);
    if (!(w > 0.0f) || !std::isfinite(points[static_cast<std::size_t>(k)].x)) continue;
    terms_[count++] = {
        point_ray_distance(points[static_cast<std::size_t>(k)], c, ray(i, k), options.cap_m), w};
  }
  return trimmed_mean(count, options.min_common, options.keep_point);
}

}  // namespace mocap::multiview
