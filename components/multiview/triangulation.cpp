#include "multiview/triangulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "multiview/observations.hpp"

namespace mocap::multiview {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool usable(const PointObservation& o, float min_confidence, std::size_t views) {
  return usable_keypoint(o.x, o.y, o.confidence, min_confidence) && o.view >= 0 &&
         static_cast<std::size_t>(o.view) < views;
}

void check_count(std::span<const PointObservation> seen) {
  if (seen.size() > static_cast<std::size_t>(kMaxViews)) {
    throw std::invalid_argument("triangulation: " + std::to_string(seen.size()) +
                                " observations of one point; at most " + std::to_string(kMaxViews) +
                                " views are supported");
  }
}

// The normal equations of the metric least squares, view by view (symmetric 3x3 and right side),
// so that subsets of views are sums of their parts.
struct Normal3 {
  std::array<double, 6> a{};  // a00 a01 a02 a11 a12 a22
  std::array<double, 3> b{};

  Normal3& operator+=(const Normal3& o) {
    for (int i = 0; i < 6; ++i) a[i] += o.a[i];
    for (int i = 0; i < 3; ++i) b[i] += o.b[i];
    return *this;
  }
  Normal3& operator-=(const Normal3& o) {
    for (int i = 0; i < 6; ++i) a[i] -= o.a[i];
    for (int i = 0; i < 3; ++i) b[i] -= o.b[i];
    return *this;
  }

  std::optional<glm::dvec3> solve() const {
    const double a00 = a[0], a01 = a[1], a02 = a[2], a11 = a[3], a12 = a[4], a22 = a[5];
    const double c00 = a11 * a22 - a12 * a12, c01 = a02 * a12 - a01 * a22,
                 c02 = a01 * a12 - a02 * a11;
    const double det = a00 * c00 + a01 * c01 + a02 * c02;
    const double trace = a00 + a11 + a22;
    // Rays closer than ~0.01 degrees to parallel leave the depth along them undetermined.
    if (!(det > 1e-9 * trace * trace * trace)) return std::nullopt;
    const double c11 = a00 * a22 - a02 * a02, c12 = a01 * a02 - a00 * a12,
                 c22 = a00 * a11 - a01 * a01;
    return glm::dvec3(c00 * b[0] + c01 * b[1] + c02 * b[2], c01 * b[0] + c11 * b[1] + c12 * b[2],
                      c02 * b[0] + c12 * b[1] + c22 * b[2]) /
           det;
  }
};

// A view's two DLT rows, (p0 - x p2) and (p1 - y p2), times `scale`.
std::array<std::array<double, 4>, 2> dlt_rows(const ViewGeometry& view, const PointObservation& o,
                                              double scale) {
  const std::array<double, 12>& p = view.projection();
  std::array<std::array<double, 4>, 2> rows{};
  for (int r = 0; r < 2; ++r) {
    const double u = r == 0 ? o.x : o.y;
    for (int c = 0; c < 4; ++c) rows[r][c] = scale * (p[4 * r + c] - u * p[8 + c]);
  }
  return rows;
}

// Rows divided by the focal length: their residual is the pixel error × depth / focal, metres.
Normal3 metric_part(const ViewGeometry& view, const PointObservation& o) {
  Normal3 n;
  for (const auto& r : dlt_rows(view, o, o.confidence / view.focal())) {
    n.a[0] += r[0] * r[0];
    n.a[1] += r[0] * r[1];
    n.a[2] += r[0] * r[2];
    n.a[3] += r[1] * r[1];
    n.a[4] += r[1] * r[2];
    n.a[5] += r[2] * r[2];
    for (int i = 0; i < 3; ++i) n.b[i] -= r[3] * r[i];
  }
  return n;
}

// The usable observations of one point and their normal-equation parts.
struct Gathered {
  std::array<PointObservation, kMaxViews> seen{};
  std::array<Normal3, kMaxViews> part{};
  int n = 0;

  Gathered(std::span<const ViewGeometry> views, std::span<const PointObservation> all,
           float min_confidence) {
    check_count(all);
    for (const PointObservation& o : all) {
      if (!usable(o, min_confidence, views.size())) continue;
      seen[n] = o;
      part[n] = metric_part(views[o.view], o);
      ++n;
    }
  }

  std::optional<glm::dvec3> solve(std::uint64_t subset) const {
    Normal3 sum;
    for (int i = 0; i < n; ++i) {
      if (subset >> i & 1u) sum += part[i];
    }
    return sum.solve();
  }
};

struct Selection {
  std::uint64_t subset = 0;  // bits of Gathered indices; 0: no point
  glm::dvec3 point{0.0};
};

// Indices i of `g` whose metric residual at `point` is at most `threshold`; bit i per index.
std::uint64_t inliers(std::span<const ViewGeometry> views, const Gathered& g,
                      const glm::dvec3& point, double threshold) {
  std::uint64_t mask = 0;
  for (int i = 0; i < g.n; ++i) {
    if (residual(views[g.seen[i].view], g.seen[i], point).m <= threshold) {
      mask |= std::uint64_t{1} << i;
    }
  }
  return mask;
}

// The point with its views (bits of `g`'s indices) and mean errors.
TriangulatedPoint finish(std::span<const ViewGeometry> views, const Gathered& g,
                         std::uint64_t subset, const glm::dvec3& point) {
  TriangulatedPoint out;
  double px = 0.0, m = 0.0;
  for (int i = 0; i < g.n; ++i) {
    if (!(subset >> i & 1u)) continue;
    const Residual r = residual(views[g.seen[i].view], g.seen[i], point);
    px += r.px;
    m += r.m;
    out.views |= std::uint64_t{1} << g.seen[i].view;
  }
  const double count = std::popcount(subset);
  out.position = glm::vec3(point);
  out.error_px = static_cast<float>(px / count);
  out.error_m = static_cast<float>(m / count);
  return out;
}

// The largest residual of a view at the point triangulated from the other views of `subset`: an
// outlier shows its whole error there, while its share of an all-view fit hides part of it (a
// quarter of four views' fit follows the outlier).
double max_held_out_residual(std::span<const ViewGeometry> views, const Gathered& g,
                             std::uint64_t subset) {
  Normal3 total;
  for (int i = 0; i < g.n; ++i) {
    if (subset >> i & 1u) total += g.part[i];
  }
  double worst = 0.0;
  for (int i = 0; i < g.n; ++i) {
    if (!(subset >> i & 1u)) continue;
    Normal3 others = total;
    others -= g.part[i];
    const auto x = others.solve();
    if (!x) return kInf;
    worst = std::max(worst, residual(views[g.seen[i].view], g.seen[i], *x).m);
  }
  return worst;
}

// Every pair of views proposes a point; the one with the least truncated cost over all views
// (MSAC: confidence × min(residual², threshold²)) is refitted on the views within the threshold.
// Counting agreeing views instead would let a pair of one outlier and one inlier win whenever
// the point between them stays within the threshold of every view.
Selection pair_consensus(std::span<const ViewGeometry> views, const Gathered& g, double threshold) {
  const double cap = threshold * threshold;
  std::uint64_t best = 0;
  double best_cost = kInf;
  for (int i = 0; i < g.n; ++i) {
    for (int j = i + 1; j < g.n; ++j) {
      const auto point = g.solve(std::uint64_t{1} << i | std::uint64_t{1} << j);
      if (!point) continue;
      double cost = 0.0;
      for (int k = 0; k < g.n; ++k) {
        const double r = residual(views[g.seen[k].view], g.seen[k], *point).m;
        cost += g.seen[k].confidence * std::min(r * r, cap);
      }
      const std::uint64_t agree = inliers(views, g, *point, threshold);
      if (std::popcount(agree) < 2 || !(cost < best_cost)) continue;
      best = agree;
      best_cost = cost;
    }
  }
  if (best == 0) return {};
  auto point = g.solve(best);
  if (!point) return {};
  // The refit may gain or lose a view at the threshold's edge: settle once.
  if (const std::uint64_t again = inliers(views, g, *point, threshold);
      again != best && std::popcount(again) >= 2) {
    if (auto refit = g.solve(again)) {
      best = again;
      point = refit;
    }
  }
  return {best, *point};
}

// Least squares over many views is dominated by the inliers: drop the worst view while any
// residual is above the threshold, then take back the dropped views that agree with the result.
Selection drop_worst(std::span<const ViewGeometry> views, const Gathered& g, double threshold) {
  std::uint64_t subset = g.n == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << g.n) - 1;
  Normal3 sum;
  for (int i = 0; i < g.n; ++i) sum += g.part[i];
  auto point = sum.solve();
  while (point) {
    int worst = -1;
    double worst_residual = threshold;
    for (int i = 0; i < g.n; ++i) {
      if (!(subset >> i & 1u)) continue;
      const double r = residual(views[g.seen[i].view], g.seen[i], *point).m;
      if (r > worst_residual) {
        worst = i;
        worst_residual = r;
      }
    }
    if (worst < 0) break;
    if (std::popcount(subset) <= 2) return {};
    subset &= ~(std::uint64_t{1} << worst);
    sum -= g.part[worst];
    point = sum.solve();
  }
  if (!point) return {};
  if (const std::uint64_t agree = inliers(views, g, *point, threshold); (agree & ~subset) != 0) {
    if (auto refit = g.solve(agree | subset)) {
      subset |= agree;
      point = refit;
    }
  }
  return {subset, *point};
}

// The views of a point that agree with each other, and the point they give.
Selection select_views(std::span<const ViewGeometry> views, const Gathered& g,
                       const RobustRule& rule) {
  const std::uint64_t all = g.n == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << g.n) - 1;
  const double threshold = rule.outlier_m;
  if (const auto point = g.solve(all)) {
    if (g.n == 2 ? inliers(views, g, *point, threshold) == all
                 : max_held_out_residual(views, g, all) <= threshold) {
      return {all, *point};
    }
  }
  return g.n <= rule.pair_search_views ? pair_consensus(views, g, threshold)
                                       : drop_worst(views, g, threshold);
}

// ---- Pose2Sim's baseline -------------------------------------------------------------------

using Matrix4 = std::array<std::array<double, 4>, 4>;

// The eigenvector of the smallest eigenvalue of a symmetric 4x4 matrix (cyclic Jacobi): the
// smallest right singular vector of the DLT matrix A, as SVD gives it, from AᵀA.
std::array<double, 4> smallest_eigenvector(Matrix4 a) {
  Matrix4 v{};
  for (int i = 0; i < 4; ++i) v[i][i] = 1.0;
  for (int sweep = 0; sweep < 50; ++sweep) {
    double off = 0.0, diagonal = 0.0;
    for (int p = 0; p < 4; ++p) {
      diagonal += a[p][p] * a[p][p];
      for (int q = p + 1; q < 4; ++q) off += a[p][q] * a[p][q];
    }
    if (off <= 1e-30 * diagonal) break;
    for (int p = 0; p < 4; ++p) {
      for (int q = p + 1; q < 4; ++q) {
        if (a[p][q] == 0.0) continue;
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
        const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::hypot(theta, 1.0));
        const double c = 1.0 / std::hypot(t, 1.0), s = t * c;
        for (int k = 0; k < 4; ++k) {  // A J
          const double kp = a[k][p], kq = a[k][q];
          a[k][p] = c * kp - s * kq;
          a[k][q] = s * kp + c * kq;
        }
        for (int k = 0; k < 4; ++k) {  // Jᵀ (A J)
          const double pk = a[p][k], qk = a[q][k];
          a[p][k] = c * pk - s * qk;
          a[q][k] = s * pk + c * qk;
        }
        for (int k = 0; k < 4; ++k) {  // V J
          const double kp = v[k][p], kq = v[k][q];
          v[k][p] = c * kp - s * kq;
          v[k][q] = s * kp + c * kq;
        }
      }
    }
  }
  int smallest = 0;
  for (int i = 1; i < 4; ++i) {
    if (a[i][i] < a[smallest][smallest]) smallest = i;
  }
  return {v[0][smallest], v[1][smallest], v[2][smallest], v[3][smallest]};
}

Matrix4 dlt_part(const ViewGeometry& view, const PointObservation& o) {
  Matrix4 m{};
  for (const auto& r : dlt_rows(view, o, o.confidence)) {
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) m[i][j] += r[i] * r[j];
    }
  }
  return m;
}

std::optional<glm::dvec3> solve_dlt(const Matrix4& ata) {
  const std::array<double, 4> h = smallest_eigenvector(ata);
  if (!(std::abs(h[3]) > 1e-12)) return std::nullopt;
  const glm::dvec3 point(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
  if (!std::isfinite(point.x) || !std::isfinite(point.y) || !std::isfinite(point.z)) {
    return std::nullopt;
  }
  return point;
}

// Pose2Sim's reprojection (common.py `reprojection`): P X / (P X)_z with no test of the side of
// the camera, and its error the plain pixel distance.
double pose2sim_error_px(const ViewGeometry& view, const PointObservation& o, const glm::dvec3& x) {
  const std::array<double, 12>& p = view.projection();
  const double w = p[8] * x.x + p[9] * x.y + p[10] * x.z + p[11];
  const double u = (p[0] * x.x + p[1] * x.y + p[2] * x.z + p[3]) / w;
  const double v = (p[4] * x.x + p[5] * x.y + p[6] * x.z + p[7]) / w;
  return std::hypot(u - o.x, v - o.y);
}

// The next `k`-combination of {0..n-1} in lexicographic order (as itertools.combinations).
bool next_combination(std::array<int, kMaxViews>& c, int k, int n) {
  int i = k - 1;
  while (i >= 0 && c[i] == n - k + i) --i;
  if (i < 0) return false;
  ++c[i];
  for (int j = i + 1; j < k; ++j) c[j] = c[j - 1] + 1;
  return true;
}

}  // namespace

void observation_residuals(std::span<const ViewGeometry> views,
                           std::span<const PointObservation> seen, const TriangulatedPoint& point,
                           std::span<float> out) {
  check_count(seen);
  std::fill(out.begin(), out.end(), std::numeric_limits<float>::quiet_NaN());
  if (!point.valid()) return;
  std::array<Normal3, kMaxViews> part{};
  Normal3 used;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    if (!usable(seen[i], 0.0f, views.size())) continue;
    part[i] = metric_part(views[seen[i].view], seen[i]);
    if (point.views >> seen[i].view & 1u) used += part[i];
  }
  const int count = point.view_count();
  for (std::size_t i = 0; i < seen.size(); ++i) {
    if (!usable(seen[i], 0.0f, views.size())) continue;
    const bool in = point.views >> seen[i].view & 1u;
    std::optional<glm::dvec3> others;
    if (count - in >= 2) {
      Normal3 n = used;
      if (in) n -= part[i];
      others = n.solve();
    }
    const glm::dvec3 at = others ? *others : glm::dvec3(point.position);
    out[i] = static_cast<float>(residual(views[seen[i].view], seen[i], at).m);
  }
}

Residual residual(const ViewGeometry& view, const PointObservation& seen, const glm::dvec3& point) {
  const double depth = view.depth(point);
  if (!(depth > 0.0)) return {kInf, kInf};
  const glm::dvec2 p = view.project(point);
  const double px = std::hypot(p.x - seen.x, p.y - seen.y);
  return {px, px * depth / view.focal()};
}

std::optional<glm::dvec3> triangulate_least_squares(std::span<const ViewGeometry> views,
                                                    std::span<const PointObservation> seen) {
  const Gathered g(views, seen, 0.0f);
  if (g.n < 2) return std::nullopt;
  return g.solve(~std::uint64_t{0});
}

std::optional<glm::dvec3> triangulate_dlt(std::span<const ViewGeometry> views,
                                          std::span<const PointObservation> seen) {
  check_count(seen);
  Matrix4 sum{};
  int n = 0;
  for (const PointObservation& o : seen) {
    if (!usable(o, 0.0f, views.size())) continue;
    const Matrix4 part = dlt_part(views[o.view], o);
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) sum[i][j] += part[i][j];
    }
    ++n;
  }
  if (n < 2) return std::nullopt;
  return solve_dlt(sum);
}

TriangulatedPoint triangulate_robust(std::span<const ViewGeometry> views,
                                     std::span<const PointObservation> seen, const RobustRule& rule,
                                     const PointPrior* prior, float* innovation_m) {
  if (innovation_m) *innovation_m = std::numeric_limits<float>::quiet_NaN();
  const Gathered g(views, seen, rule.min_confidence);
  Normal3 prior_part;
  if (prior) {
    const double w = prior->weight;
    prior_part.a = {w, 0.0, 0.0, w, 0.0, w};
    prior_part.b = {w * prior->point.x, w * prior->point.y, w * prior->point.z};
  }
  if (g.n == 1 && prior) {
    // One view fixes two directions, the prediction the depth along its ray: kept when the view
    // agrees with the prediction.
    Normal3 sum = g.part[0];
    sum += prior_part;
    const auto point = sum.solve();
    if (!point || residual(views[g.seen[0].view], g.seen[0], prior->point).m > rule.outlier_m) {
      return {};
    }
    return finish(views, g, 1, *point);
  }
  if (g.n < 2) return {};
  Selection s = select_views(views, g, rule);
  if (s.subset == 0) return {};
  if (prior) {
    if (innovation_m && std::popcount(s.subset) >= 3) {
      *innovation_m = static_cast<float>(glm::distance(s.point, prior->point));
    }
    Normal3 sum = prior_part;
    for (int i = 0; i < g.n; ++i) {
      if (s.subset >> i & 1u) sum += g.part[i];
    }
    if (const auto fused = sum.solve()) s.point = *fused;
  }
  return finish(views, g, s.subset, s.point);
}

void held_out_residuals(std::span<const ViewGeometry> views, std::span<const PointObservation> seen,
                        const RobustRule& rule, std::vector<float>& out,
                        std::vector<float>& two_view_gaps) {
  const TriangulatedPoint point = triangulate_robust(views, seen, rule);
  if (point.view_count() == 2) {
    two_view_gaps.push_back(2.0f * point.error_m);  // the two residuals add up to the rays' gap
    return;
  }
  if (point.view_count() < 3) return;
  const Gathered g(views, seen, rule.min_confidence);
  std::uint64_t used = 0;
  for (int i = 0; i < g.n; ++i) {
    if (point.views >> g.seen[i].view & 1u) used |= std::uint64_t{1} << i;
  }
  Normal3 total;
  for (int i = 0; i < g.n; ++i) {
    if (used >> i & 1u) total += g.part[i];
  }
  for (int i = 0; i < g.n; ++i) {
    if (!(used >> i & 1u)) continue;
    Normal3 others = total;
    others -= g.part[i];
    if (const auto x = others.solve()) {
      out.push_back(static_cast<float>(residual(views[g.seen[i].view], g.seen[i], *x).m));
    }
  }
}

TriangulatedPoint triangulate_pose2sim(std::span<const ViewGeometry> views,
                                       std::span<const PointObservation> seen,
                                       const Pose2SimRule& rule) {
  check_count(seen);
  std::array<PointObservation, kMaxViews> kept{};
  std::array<Matrix4, kMaxViews> part{};
  int n = 0;
  for (const PointObservation& o : seen) {
    // Pose2Sim sets likelihoods below the threshold to NaN and leaves out NaN and zero ones.
    if (!usable(o, 0.0f, views.size()) || o.confidence < rule.likelihood_threshold) continue;
    kept[n] = o;
    part[n] = dlt_part(views[o.view], o);
    ++n;
  }
  for (int size = n; size >= std::max(rule.min_views, 2); --size) {
    double best_error = kInf;
    std::uint64_t best_subset = 0;
    glm::dvec3 best_point{0.0};
    std::array<int, kMaxViews> c{};
    for (int i = 0; i < size; ++i) c[i] = i;
    do {
      Matrix4 sum{};
      for (int i = 0; i < size; ++i) {
        for (int r = 0; r < 4; ++r) {
          for (int s = 0; s < 4; ++s) sum[r][s] += part[c[i]][r][s];
        }
      }
      const auto point = solve_dlt(sum);
      if (!point) continue;
      double error = 0.0;
      for (int i = 0; i < size; ++i)
        error += pose2sim_error_px(views[kept[c[i]].view], kept[c[i]], *point);
      error /= size;
      if (error < best_error) {  // strict: the first of equal subsets, as numpy's nanargmin
        best_error = error;
        best_point = *point;
        best_subset = 0;
        for (int i = 0; i < size; ++i) best_subset |= std::uint64_t{1} << kept[c[i]].view;
      }
    } while (next_combination(c, size, n));
    if (best_error <= rule.reprojection_px) {
      TriangulatedPoint out;
      out.position = glm::vec3(best_point);
      out.views = best_subset;
      out.error_px = static_cast<float>(best_error);
      double metres = 0.0;
      for (int i = 0; i < n; ++i) {
        if (best_subset >> kept[i].view & 1u) {
          metres += residual(views[kept[i].view], kept[i], best_point).m;
        }
      }
      out.error_m = static_cast<float>(metres / size);
      return out;
    }
  }
  return {};
}

}  // namespace mocap::multiview
