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

}  // namespace

TallestPerson tallest_person(const std::vector<camera::BodyKeypoints>& people,
                             double min_confidence) {
  TallestPerson best;
  for (std::size_t p = 0; p < people.size(); ++p) {
    float top = std::numeric_limits<float>::max(), bottom = std::numeric_limits<float>::lowest();
    for (const Keypoint2D& k : people[p]) {
      if (!(k.confidence >= min_confidence) || !std::isfinite(k.y)) continue;
      top = std::min(top, k.y);
      bottom = std::max(bottom, k.y);
    }
    if (bottom >= top && (best.index < 0 || bottom - top > best.height_px)) {
      best.height_px = bottom - top;
      best.index = static_cast<int>(p);
    }
  }
  return best;
}

ViewResiduals view_residuals(std::span<const camera::Camera> cameras,
                             std::span<const camera::BodySequence> views,
                             const ViewErrorOptions& options) {
  if (cameras.size() != views.size())
    throw std::invalid_argument("view_errors: one view per camera expected");
  ViewResiduals out;
  out.views.resize(views.size());
  if (views.empty()) return out;
  out.frames = std::min_element(views.begin(), views.end(), [](const auto& a, const auto& b) {
                 return a.size() < b.size();
               })->size();
  if (views.size() < 3) return out;  // a view's joint needs two others to triangulate from
  std::vector<ViewGeometry> geometry;
  for (const camera::Camera& c : cameras) geometry.push_back(from_camera(c));
  std::vector<PointObservation> others;
  std::vector<int> person(views.size());
  for (std::size_t f = 0; f < out.frames; ++f) {
    for (std::size_t v = 0; v < views.size(); ++v)
      person[v] = tallest_person(views[v][f], options.min_confidence).index;
    if (std::find(person.begin(), person.end(), -1) != person.end()) continue;
    ++out.frames_used;
    for (int j = 0; j < kBodyJoints; ++j) {
      // Every view's keypoint of this joint, undistorted; confidence 0 when not usable.
      std::vector<PointObservation> seen(views.size());
      std::vector<glm::dvec2> read(views.size());
      for (std::size_t v = 0; v < views.size(); ++v) {
        const Keypoint2D& k =
            views[v][f][static_cast<std::size_t>(person[v])][static_cast<std::size_t>(j)];
        seen[v].view = static_cast<int>(v);
        if (!(k.confidence >= options.min_confidence) || !std::isfinite(k.x) || !std::isfinite(k.y))
          continue;
        read[v] = {k.x, k.y};
        const glm::dvec2 u = cameras[v].undistort_pixel(read[v]);
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
        if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
        out.views[v].push_back({read[v], glm::dvec2(seen[v].x, seen[v].y), p});
      }
    }
  }
  return out;
}

ViewErrorReport view_errors(std::span<const camera::Camera> cameras,
                            std::span<const camera::BodySequence> views,
                            const ViewErrorOptions& options) {
  const ViewResiduals residuals = view_residuals(cameras, views, options);
  ViewErrorReport report;
  report.views.resize(views.size());
  report.frames = residuals.frames;
  report.frames_used = residuals.frames_used;
  for (std::size_t v = 0; v < views.size(); ++v) {
    std::vector<double> errors;
    for (const ViewResidual& r : residuals.views[v])
      errors.push_back(
          std::hypot(r.projected.x - r.undistorted.x, r.projected.y - r.undistorted.y));
    ViewError& out = report.views[v];
    out.points = errors.size();
    if (errors.empty()) continue;
    out.mean_px =
        std::accumulate(errors.begin(), errors.end(), 0.0) / static_cast<double>(errors.size());
    out.median_px = median(errors);
  }
  flag_views(report, options);
  return report;
}

void flag_views(ViewErrorReport& report, const ViewErrorOptions& options) {
  for (std::size_t v = 0; v < report.views.size(); ++v) {
    report.views[v].flagged = false;
    const double typical = others_median(report, v);
    if (std::isnan(typical) || report.views[v].points == 0) continue;
    report.views[v].flagged = report.views[v].median_px > options.min_flag_px &&
                              report.views[v].median_px > options.flag_ratio * typical;
  }
}

double others_median(const ViewErrorReport& report, std::size_t view) {
  std::vector<double> rest;
  for (std::size_t o = 0; o < report.views.size(); ++o)
    if (o != view && report.views[o].points > 0) rest.push_back(report.views[o].median_px);
  return rest.empty() ? std::numeric_limits<double>::quiet_NaN() : median(rest);
}

}  // namespace mocap::multiview
