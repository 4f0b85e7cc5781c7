#include "eval/procrustes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace mocap::eval {
namespace {

constexpr int kMaxSweeps = 60;

// Rotates columns p and q of w (and of v alike) so that they become orthogonal. Returns false
// when they already are, to working precision.
bool orthogonalise(glm::dmat3& w, glm::dmat3& v, int p, int q) {
  const double alpha = glm::dot(w[p], w[p]);
  const double beta = glm::dot(w[q], w[q]);
  const double gamma = glm::dot(w[p], w[q]);
  if (gamma == 0.0 || std::abs(gamma) <= 1e-15 * std::sqrt(alpha * beta)) return false;
  const double zeta = (beta - alpha) / (2.0 * gamma);
  const double t = std::copysign(1.0, zeta) / (std::abs(zeta) + std::sqrt(1.0 + zeta * zeta));
  const double c = 1.0 / std::sqrt(1.0 + t * t);
  const double s = c * t;
  for (glm::dmat3* m : {&w, &v}) {
    const glm::dvec3 cp = (*m)[p], cq = (*m)[q];
    (*m)[p] = c * cp - s * cq;
    (*m)[q] = s * cp + c * cq;
  }
  return true;
}

// Any unit vector orthogonal to the unit vector a.
glm::dvec3 orthogonal_to(const glm::dvec3& a) {
  const glm::dvec3 axis = std::abs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(a, axis));
}

// Columns with (relatively) zero singular value carry no direction: complete U to an
// orthonormal, right-handed basis from the columns that do.
void complete_basis(glm::dmat3& u, const glm::dvec3& singular) {
  const double tiny = 1e-12 * singular[0];
  int rank = 0;
  while (rank < 3 && singular[rank] > tiny && singular[rank] > 0.0) ++rank;
  if (rank == 0) u = glm::dmat3(1.0);
  if (rank == 1) u[1] = orthogonal_to(u[0]);
  if (rank <= 2 && rank > 0) u[2] = glm::cross(u[0], u[1]);
}

bool finite(const glm::dmat3& m) {
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      if (!std::isfinite(m[c][r])) return false;
    }
  }
  return true;
}

}  // namespace

Svd3 svd3(const glm::dmat3& a) {
  if (!finite(a)) {
    const double nan = std::nan("");
    return {glm::dmat3(nan), glm::dvec3(nan), glm::dmat3(nan)};
  }
  glm::dmat3 w = a, v(1.0);
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    bool rotated = orthogonalise(w, v, 0, 1);
    rotated = orthogonalise(w, v, 0, 2) || rotated;
    rotated = orthogonalise(w, v, 1, 2) || rotated;
    if (!rotated) break;
  }
  std::array<int, 3> order = {0, 1, 2};
  std::array<double, 3> norm = {glm::length(w[0]), glm::length(w[1]), glm::length(w[2])};
  std::sort(order.begin(), order.end(), [&](int i, int j) { return norm[i] > norm[j]; });
  Svd3 out;
  for (int k = 0; k < 3; ++k) {
    const int i = order[k];
    out.singular[k] = norm[i];
    out.v[k] = v[i];
    out.u[k] = norm[i] > 0.0 ? w[i] / norm[i] : glm::dvec3(0.0);
  }
  complete_basis(out.u, out.singular);
  return out;
}

Similarity procrustes(std::span<const glm::dvec3> from, std::span<const glm::dvec3> to,
                      Alignment alignment) {
  if (from.size() != to.size() || from.empty()) {
    throw std::invalid_argument("procrustes: point sets must have the same, non-zero size");
  }
  const double n = static_cast<double>(from.size());
  glm::dvec3 mean_from(0.0), mean_to(0.0);
  for (std::size_t i = 0; i < from.size(); ++i) mean_from += from[i], mean_to += to[i];
  mean_from /= n;
  mean_to /= n;
  glm::dmat3 covariance(0.0);  // Σ (to − mean_to)(from − mean_from)ᵀ / n
  double variance_from = 0.0;
  for (std::size_t i = 0; i < from.size(); ++i) {
    const glm::dvec3 x = from[i] - mean_from, y = to[i] - mean_to;
    covariance += glm::outerProduct(y, x);
    variance_from += glm::dot(x, x);
  }
  covariance /= n;
  variance_from /= n;

  Similarity out;
  if (variance_from > 0.0) {
    const Svd3 svd = svd3(covariance);
    // A reflection would fit better when det(U)·det(V) < 0; flip the weakest direction instead.
    glm::dvec3 sign(1.0);
    if (glm::determinant(svd.u) * glm::determinant(svd.v) < 0.0) sign.z = -1.0;
    glm::dmat3 signed_u = svd.u;
    signed_u[2] *= sign.z;
    out.rotation = signed_u * glm::transpose(svd.v);
    if (alignment == Alignment::similarity) {
      out.scale = glm::dot(svd.singular, sign) / variance_from;
    }
  }
  out.translation = mean_to - out.scale * (out.rotation * mean_from);
  return out;
}

}  // namespace mocap::eval
