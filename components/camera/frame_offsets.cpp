#include "camera/frame_offsets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "camera/camera.hpp"
#include "core/keypoint_layout.hpp"

namespace mocap::camera {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kFrameCostCap = 0.5;  // person heights: a person matching nobody counts this

// One person's undistorted joints (NaN where missing) and height in pixels.
struct Figure {
  std::array<glm::dvec3, kBodyJoints> points{};  // homogeneous pixels
  std::array<bool, kBodyJoints> known{};
  double height = 0;
};

std::vector<std::vector<Figure>> figures_of(const Camera& camera, const BodySequence& view,
                                            double min_confidence) {
  std::vector<std::vector<Figure>> out(view.size());
  std::vector<std::array<float, 2>> pixels(kBodyJoints);
  for (std::size_t t = 0; t < view.size(); ++t) {
    for (const BodyKeypoints& body : view[t]) {
      Figure f;
      for (int j = 0; j < kBodyJoints; ++j) pixels[j] = {body[j].x, body[j].y};
      camera.undistort_pixels(pixels);
      double top = std::numeric_limits<double>::infinity(), bottom = -top;
      int known = 0;
      for (int j = 0; j < kBodyJoints; ++j) {
        const bool ok = body[j].confidence >= min_confidence && std::isfinite(pixels[j][0]) &&
                        std::isfinite(pixels[j][1]);
        f.known[j] = ok;
        if (!ok) continue;
        f.points[j] = {pixels[j][0], pixels[j][1], 1.0};
        top = std::min(top, f.points[j].y);
        bottom = std::max(bottom, f.points[j].y);
        ++known;
      }
      f.height = bottom - top;
      if (known >= 6 && f.height > 10.0) out[t].push_back(f);
    }
  }
  return out;
}

glm::dmat3 cross_matrix(const glm::dvec3& v) {  // [v]x, column-major
  return glm::dmat3(0, v.z, -v.y, -v.z, 0, v.x, v.y, -v.x, 0);
}

glm::dmat3 intrinsics(const Camera& c) {  // K, column-major
  return glm::dmat3(c.fx, 0, 0, 0, c.fy, 0, c.cx, c.cy, 1);
}

// F with x_view^T F x_ref = 0 for the same point seen by both cameras.
glm::dmat3 fundamental(const Camera& ref, const Camera& view) {
  const glm::dmat3 r = view.rotation * glm::transpose(ref.rotation);  // ref camera -> view camera
  const glm::dvec3 t = view.translation - r * ref.translation;
  const glm::dmat3 essential = cross_matrix(t) * r;
  return glm::transpose(glm::inverse(intrinsics(view))) * essential * glm::inverse(intrinsics(ref));
}

// The symmetric epipolar distances of the joints both know, in `v`'s heights: their trimmed mean.
double pair_cost(const glm::dmat3& f, const Figure& ref, const Figure& v) {
  std::array<double, kBodyJoints> d{};
  int n = 0;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (!ref.known[j] || !v.known[j]) continue;
    const glm::dvec3 line_in_view = f * ref.points[j];
    const glm::dvec3 line_in_ref = glm::transpose(f) * v.points[j];
    const double e = glm::dot(v.points[j], line_in_view);
    const double a = std::hypot(line_in_view.x, line_in_view.y);
    const double b = std::hypot(line_in_ref.x, line_in_ref.y);
    if (!(a > 0) || !(b > 0)) continue;
    d[n++] = 0.5 * (std::abs(e) / a + std::abs(e) / b);
  }
  if (n < 4) return kFrameCostCap;
  // The mean of the best 80 %: the noise of every joint averages out, a wrong keypoint does not
  // count.
  for (int i = 1; i < n; ++i)  // insertion sort: at most 15 values
    for (int k = i; k > 0 && d[k] < d[k - 1]; --k) std::swap(d[k], d[k - 1]);
  const int kept = std::max(3, (4 * n) / 5);
  double sum = 0;
  for (int i = 0; i < kept; ++i) sum += d[i];
  return std::min(kFrameCostCap, sum / kept / v.height);
}

// Mean over the view's frames with people of the per-person best cost (NaN: fewer than
// min_overlap such frames with the reference frame in range).
double cost_at(const glm::dmat3& f, const std::vector<std::vector<Figure>>& ref,
               const std::vector<std::vector<Figure>>& view, int lag, int min_overlap) {
  double sum = 0;
  int frames = 0;
  for (std::size_t t = 0; t < view.size(); ++t) {
    const long r = static_cast<long>(t) + lag;
    if (r < 0 || r >= static_cast<long>(ref.size()) || view[t].empty() ||
        ref[static_cast<std::size_t>(r)].empty())
      continue;
    double frame = 0;
    for (const Figure& v : view[t]) {
      double best = kFrameCostCap;
      for (const Figure& q : ref[static_cast<std::size_t>(r)])
        best = std::min(best, pair_cost(f, q, v));
      frame += best;
    }
    sum += frame / static_cast<double>(view[t].size());
    ++frames;
  }
  return frames >= min_overlap ? sum / frames : kNaN;
}

std::string percent(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f %%", 100.0 * v);
  return text;
}

ViewOffset offset_from_costs(const std::vector<double>& cost, int range, double min_contrast) {
  ViewOffset out;
  std::size_t best = cost.size();
  for (std::size_t i = 0; i < cost.size(); ++i)
    if (std::isfinite(cost[i]) && (best == cost.size() || cost[i] < cost[best])) best = i;
  if (best == cost.size()) {
    out.problem = "no frames with people in both views at any offset";
    return out;
  }
  std::vector<double> finite;
  for (const double c : cost)
    if (std::isfinite(c)) finite.push_back(c);
  std::nth_element(finite.begin(), finite.begin() + finite.size() / 2, finite.end());
  const double typical = finite[finite.size() / 2];
  out.frames = static_cast<double>(static_cast<int>(best) - range);
  if (best > 0 && best + 1 < cost.size() && std::isfinite(cost[best - 1]) &&
      std::isfinite(cost[best + 1])) {
    // The cost grows like |offset error| (people move across the lines at a speed): a V, not a
    // parabola, through the minimum and its neighbours.
    const double l = cost[best - 1], c = cost[best], r = cost[best + 1];
    if (const double rise = std::max(l, r) - c; rise > 0)
      out.frames += std::clamp(0.5 * (l - r) / rise, -0.5, 0.5);
  }
  out.cost = cost[best];
  out.contrast = typical > 0 ? 1.0 - cost[best] / typical : 0.0;
  if (out.contrast < min_contrast) {
    out.problem = "too little motion across the epipolar lines: the best offset fits " +
                  percent(cost[best]) + " of a body height off, a typical one " + percent(typical);
  } else if (best == 0 || best + 1 == cost.size()) {
    out.problem = "the best match is at the edge of the search (" +
                  std::to_string(static_cast<int>(out.frames)) + " frames): it may be further";
  } else {
    out.found = true;
  }
  return out;
}

}  // namespace

BodySequence body_sequence(std::span<const People2D> frames) {
  BodySequence out(frames.size());
  std::vector<float> xyc;
  std::array<float, 3 * kBodyJoints> body{};
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const KeypointLayout& l = layout(frames[f].layout);
    for (const Person2D& p : frames[f].people) {
      if (p.joints.size() != l.keypoints.size()) continue;  // not this layout: skipped
      xyc.clear();
      for (const Keypoint2D& k : p.joints) xyc.insert(xyc.end(), {k.x, k.y, k.confidence});
      to_body15(l, xyc, body);
      BodyKeypoints b;
      for (int j = 0; j < kBodyJoints; ++j) b[j] = {body[3 * j], body[3 * j + 1], body[3 * j + 2]};
      out[f].push_back(b);
    }
  }
  return out;
}

std::vector<ViewOffset> estimate_offsets(std::span<const Camera> cameras,
                                         std::span<const BodySequence> views, std::size_t reference,
                                         const OffsetOptions& options) {
  std::vector<ViewOffset> out(views.size());
  if (cameras.size() != views.size() || reference >= views.size()) {
    for (ViewOffset& o : out)
      o.problem = std::to_string(cameras.size()) + " cameras for " + std::to_string(views.size()) +
                  " views (reference " + std::to_string(reference) + ")";
    return out;
  }
  const auto ref = figures_of(cameras[reference], views[reference], options.min_confidence);
  const int range = options.max_offset_frames;
  for (std::size_t v = 0; v < views.size(); ++v) {
    if (v == reference) {
      out[v].found = true;
      continue;
    }
    const auto figures = figures_of(cameras[v], views[v], options.min_confidence);
    const glm::dmat3 f = fundamental(cameras[reference], cameras[v]);
    std::vector<double> cost;
    for (int lag = -range; lag <= range; ++lag)
      cost.push_back(cost_at(f, ref, figures, lag, options.min_overlap_frames));
    out[v] = offset_from_costs(cost, range, options.min_contrast);
  }
  return out;
}

}  // namespace mocap::camera
