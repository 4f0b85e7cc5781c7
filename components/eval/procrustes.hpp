#pragma once
// The singular value decomposition of a 3×3 matrix and the similarity Procrustes alignment
// (Umeyama 1991) built on it: the rotation, uniform scale and translation that best map one
// point set onto another in the least-squares sense. No reflection is ever returned.

#include <span>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace mocap::eval {

// A = U · diag(singular) · Vᵀ with U, V orthogonal and singular values sorted, largest first,
// all >= 0. det(U) and det(V) may be -1. Rank-deficient input gets a complete orthonormal U.
struct Svd3 {
  glm::dmat3 u{1.0};
  glm::dvec3 singular{0.0};
  glm::dmat3 v{1.0};
};

// One-sided Jacobi: rotates the columns of A until they are orthogonal (at most 60 sweeps;
// converges in a handful for 3×3). Non-finite input gives non-finite output, never a hang.
Svd3 svd3(const glm::dmat3& a);

// x ↦ scale · rotation · x + translation.
struct Similarity {
  glm::dmat3 rotation{1.0};  // proper: det = +1
  double scale = 1.0;
  glm::dvec3 translation{0.0};

  glm::dvec3 apply(const glm::dvec3& x) const { return scale * (rotation * x) + translation; }
};

enum class Alignment { similarity, rigid };  // rigid: scale fixed at 1

// Minimises Σ |T(from_i) − to_i|² over proper rotations, translations and (for `similarity`)
// scales > 0. The sets must have the same, non-zero size. If `from` is a single point repeated,
// rotation and scale are undefined; the identity and scale 1 are returned.
Similarity procrustes(std::span<const glm::dvec3> from, std::span<const glm::dvec3> to,
                      Alignment alignment = Alignment::similarity);

}  // namespace mocap::eval
