#include "multiview/view_errors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "multiview/rig_reconstruction.hpp"
#include "multiview/triangulation.hpp"

namespace mocap::multiview {
namespace {

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The frame's tallest person by the vertical span of its confident keypoints; -1: nobody.
int tallest(const std::vector<camera::BodyKeypoints>& people, double min_confidence) {
  int best = -1;
  float best_span = -1;
  for (std::size_t p = 0; p < people.size(); ++p) {
    float top = std::numeric_limits<float>::max(), bottom = std::numeric_limits<float>::lowest();
    for (const Keypoint2D& k : people[p]) {
      if (!(k.confidence >= min_confidence) || !std::isfinite(k.y)) continue;
      top = std::min(top, k.y);
      bottom = std::max(bottom, k.y);
    }
    if (bottom >= top && bottom - top > best_span) {
      best_span = bottom - top;
      best = static_cast<int>(p);
    }
  }
  return best;
}

}  // namespace

ViewErrorReport view_errors(std::span<const camera::Camera> cameras,
                            std::span<const camera::BodySequence> views,
                            const ViewErrorOptions& options) {
  if (cameras.size() != views.size())
    throw std::invalid_argument("view_errors: one view per camera expected");
  ViewErrorReport report;
  report.views.resize(views.size());
  if (views.size() < 3) return report;  // a view's joint needs two others to triangulate from
  std::vector<ViewGeometry> geometry;
  for (const camera::Camera& c : cameras) geometry.push_back(from_camera(c));
  report.frames = std::min_element(views.begin(), views.end(), [](const auto& a, const auto& b) {
                    return a.size() < b.size();
                  })->size();
  std::vector<std::vector<double>> errors(views.size());
  std::vector<PointObservation> others;
  std::vector<int> person(views.size());
  for (std::size_t f = 0; f < report.frames; ++f) {
    for (std::size_t v = 0; v < views.size(); ++v)
      person[v] = tallest(views[v][f], options.min_confidence);
    if (std::find(person.begin(), person.end(), -1) != person.end()) continue;
    ++report.frames_used;
    for (int j = 0; j < kBodyJoints; ++j) {
      // Every view's keypoint of this joint, undistorted; confidence 0 when not usable.
      std::vector<PointObservation> seen(views.size());
      for (std::size_t v = 0; v < views.size(); ++v) {
        const Keypoint2D& k =
            views[v][f][static_cast<std::size_t>(person[v])][static_cast<std::size_t>(j)];
        seen[v].view = static_cast<int>(v);
        if (!(k.confidence >= options.min_confidence) || !std::isfinite(k.x) || !std::isfinite(k.y))
          continue;
        const glm::dvec2 u = cameras[v].undistort_pixel({k.x, k.y});
        seen[v] = {static_cast<int>(v), static_cast<float>(u.x), static_cast<float>(u.y),
                   k.confidence};
      }
      for (std::size_t v = 0; v < views.size(); ++v) {
        if (seen[v].confidence <= 0) continue;
        others.clear();
        for (std::size_t o = 0; o < views.size(); ++o)
          if (o != v && seen[o].confidence > 0) others.push_back(seen[o]);
        if (others.size() < 2) continue;
        // The others' consensus: one of them far off (a worse camera) is left out rather than
        // pulling the point, and with it this camera's error, its way.
        const TriangulatedPoint point = triangulate_robust(geometry, others);
        if (!point.valid() || point.view_count() < 2) continue;
        const glm::dvec3 world(point.position);
        if (geometry[v].depth(world) <= 0) continue;
        const glm::dvec2 p = geometry[v].project(world);
        const double error = std::hypot(p.x - seen[v].x, p.y - seen[v].y);
        if (std::isfinite(error)) errors[v].push_back(error);
      }
    }
  }
  std::vector<double> medians;
  for (std::size_t v = 0; v < views.size(); ++v) {
    ViewError& out = report.views[v];
    out.points = errors[v].size();
    if (errors[v].empty()) continue;
    out.mean_px = std::accumulate(errors[v].begin(), errors[v].end(), 0.0) /
                  static_cast<double>(errors[v].size());
    out.median_px = median(errors[v]);
  }
  for (std::size_t v = 0; v < views.size(); ++v) {
    std::vector<double> rest;
    for (std::size_t o = 0; o < views.size(); ++o)
      if (o != v && report.views[o].points > 0) rest.push_back(report.views[o].median_px);
    if (rest.empty() || report.views[v].points == 0) continue;
    const double typical = median(rest);
    report.views[v].flagged = report.views[v].median_px > options.min_flag_px &&
                              report.views[v].median_px > options.flag_ratio * typical;
  }
  return report;
}

}  // namespace mocap::multiview
