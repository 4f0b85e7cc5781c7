#include "eval/procrustes.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/matrix.hpp>

#include <gtest/gtest.h>

namespace mocap::eval {
namespace {

glm::dmat3 rotation(double angle, glm::dvec3 axis) {
  return glm::dmat3(glm::rotate(glm::dmat4(1.0), angle, glm::normalize(axis)));
}

void expect_near(const glm::dmat3& a, const glm::dmat3& b, double tolerance) {
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r)
      EXPECT_NEAR(a[c][r], b[c][r], tolerance) << "column " << c << " row " << r;
  }
}

void expect_orthonormal(const glm::dmat3& m) {
  expect_near(glm::transpose(m) * m, glm::dmat3(1.0), 1e-12);
}

glm::dmat3 reassemble(const Svd3& s) {
  glm::dmat3 d(0.0);
  for (int i = 0; i < 3; ++i) d[i][i] = s.singular[i];
  return s.u * d * glm::transpose(s.v);
}

TEST(Svd3, ReassemblesRandomMatrices) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-3.0, 3.0);
  for (int trial = 0; trial < 200; ++trial) {
    glm::dmat3 a;
    for (int c = 0; c < 3; ++c) a[c] = {value(rng), value(rng), value(rng)};
    const Svd3 s = svd3(a);
    expect_orthonormal(s.u);
    expect_orthonormal(s.v);
    EXPECT_GE(s.singular[0], s.singular[1]);
    EXPECT_GE(s.singular[1], s.singular[2]);
    EXPECT_GE(s.singular[2], 0.0);
    expect_near(reassemble(s), a, 1e-10);
  }
}

TEST(Svd3, DiagonalWithNegativeEntry) {
  // diag(-3, 2, 1): singular values 3, 2, 1 and one of U, V carries the sign.
  const glm::dmat3 a(glm::dvec3(-3, 0, 0), glm::dvec3(0, 2, 0), glm::dvec3(0, 0, 1));
  const Svd3 s = svd3(a);
  EXPECT_NEAR(s.singular[0], 3.0, 1e-14);
  EXPECT_NEAR(s.singular[1], 2.0, 1e-14);
  EXPECT_NEAR(s.singular[2], 1.0, 1e-14);
  EXPECT_NEAR(glm::determinant(s.u) * glm::determinant(s.v), -1.0, 1e-12);
  expect_near(reassemble(s), a, 1e-12);
}

TEST(Svd3, RankDeficientMatricesGetACompleteBasis) {
  // Rank 2 (third column = first + second) and rank 1 (outer product) and zero.
  glm::dmat3 rank2(glm::dvec3(1, 2, 3), glm::dvec3(-1, 0, 4), glm::dvec3(0, 2, 7));
  glm::dmat3 rank1 = glm::outerProduct(glm::dvec3(1, -2, 0.5), glm::dvec3(3, 1, 2));
  for (const glm::dmat3& a : {rank2, rank1, glm::dmat3(0.0)}) {
    const Svd3 s = svd3(a);
    expect_orthonormal(s.u);
    expect_orthonormal(s.v);
    expect_near(reassemble(s), a, 1e-10);
  }
  EXPECT_NEAR(svd3(rank2).singular[2], 0.0, 1e-12);
  EXPECT_NEAR(svd3(rank1).singular[1], 0.0, 1e-12);
}

TEST(Svd3, NonFiniteInputGivesNaNNotAHang) {
  glm::dmat3 a(1.0);
  a[1][2] = std::nan("");
  EXPECT_TRUE(std::isnan(svd3(a).singular[0]));
}

std::vector<glm::dvec3> chiral_points() {
  return {{0.1, 0.2, 0.3}, {-0.4, 0.1, 0.0}, {0.3, -0.2, 0.5}, {0.0, 0.7, -0.1}, {0.9, 0.1, 0.2}};
}

TEST(Procrustes, RecoversAKnownSimilarity) {
  const glm::dmat3 r = rotation(1.1, {0.3, -1.0, 0.4});
  const double scale = 1.7;
  const glm::dvec3 t(0.5, -2.0, 3.0);
  const auto from = chiral_points();
  std::vector<glm::dvec3> to;
  for (const auto& x : from) to.push_back(scale * (r * x) + t);
  const Similarity fit = procrustes(from, to);
  expect_near(fit.rotation, r, 1e-12);
  EXPECT_NEAR(fit.scale, scale, 1e-12);
  EXPECT_NEAR(fit.translation.x, t.x, 1e-12);
  EXPECT_NEAR(fit.translation.y, t.y, 1e-12);
  EXPECT_NEAR(fit.translation.z, t.z, 1e-12);
  EXPECT_NEAR(procrustes(from, to, Alignment::rigid).scale, 1.0, 0.0);
}

// Six points ±a·x, ±b·y, ±c·z (a > b > c) and their mirror image x → −x, point by point.
// Cross-covariance ∝ diag(−a², b², c²): U = diag(−1, 1, 1), V = I, det(U)·det(V) = −1, so the
// sign flips the weakest axis: R = diag(−1, 1, −1) (a half turn about y) and
// s = (a² + b² − c²)/(a² + b² + c²). With a, b, c = 0.3, 0.2, 0.1: s = 12/14 = 6/7 and the
// residuals are |1 − s|·a = 3/70, (1 − s)·b = 2/70 and (1 + s)·c = 13/70 (two points each):
// mean 6/70 = 0.0857142857.
TEST(Procrustes, MirrorImageGetsTheBestProperRotation) {
  const double a = 0.3, b = 0.2, c = 0.1;
  const std::vector<glm::dvec3> from = {{a, 0, 0},  {-a, 0, 0}, {0, b, 0},
                                        {0, -b, 0}, {0, 0, c},  {0, 0, -c}};
  std::vector<glm::dvec3> to;
  for (const auto& x : from) to.push_back({-x.x, x.y, x.z});
  const Similarity fit = procrustes(from, to);
  EXPECT_NEAR(glm::determinant(fit.rotation), 1.0, 1e-12);
  expect_near(fit.rotation,
              glm::dmat3(glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, -1)), 1e-12);
  EXPECT_NEAR(fit.scale, 6.0 / 7.0, 1e-12);
  double mean = 0.0;
  for (std::size_t i = 0; i < from.size(); ++i) mean += glm::length(fit.apply(from[i]) - to[i]);
  EXPECT_NEAR(mean / 6.0, 6.0 / 70.0, 1e-12);
}

// A planar set and its mirror image within the plane: a half turn about the in-plane axis
// maps one onto the other exactly, so no reflection is needed and the error is zero.
TEST(Procrustes, PlanarMirrorIsAHalfTurn) {
  const std::vector<glm::dvec3> from = {
      {0.1, 0.2, 0}, {-0.4, 0.1, 0}, {0.3, -0.5, 0}, {0.7, 0.6, 0}};
  std::vector<glm::dvec3> to;
  for (const auto& x : from) to.push_back({-x.x, x.y, 0.0});
  const Similarity fit = procrustes(from, to);
  EXPECT_NEAR(glm::determinant(fit.rotation), 1.0, 1e-12);
  EXPECT_NEAR(fit.scale, 1.0, 1e-12);
  for (std::size_t i = 0; i < from.size(); ++i)
    EXPECT_NEAR(glm::length(fit.apply(from[i]) - to[i]), 0.0, 1e-12);
}

// No random proper rotation (with its best scale and translation) beats the solution.
TEST(Procrustes, IsOptimalAgainstRandomRotations) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  const auto from = chiral_points();
  std::vector<glm::dvec3> to;
  for (const auto& x : from)
    to.push_back(glm::dvec3(-x.x, x.z, x.y) + glm::dvec3(noise(rng), noise(rng), noise(rng)));
  const auto cost = [&](const Similarity& s) {
    double sum = 0.0;
    for (std::size_t i = 0; i < from.size(); ++i) {
      const glm::dvec3 d = s.apply(from[i]) - to[i];
      sum += glm::dot(d, d);
    }
    return sum;
  };
  const double best = cost(procrustes(from, to));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const glm::dmat3 r = rotation(3.2 * u(rng), {u(rng), u(rng), u(rng) + 1e-3});
    // The best scale and translation for this fixed rotation, in closed form.
    Similarity s;
    s.rotation = r;
    glm::dvec3 mf(0.0), mt(0.0);
    for (std::size_t i = 0; i < from.size(); ++i) mf += from[i], mt += to[i];
    mf /= 5.0, mt /= 5.0;
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < from.size(); ++i) {
      num += glm::dot(r * (from[i] - mf), to[i] - mt);
      den += glm::dot(from[i] - mf, from[i] - mf);
    }
    s.scale = std::max(0.0, num / den);  // a negative scale would be a reflection
    s.translation = mt - s.scale * (r * mf);
    EXPECT_GE(cost(s), best - 1e-12);
  }
}

TEST(Procrustes, DegenerateInput) {
  const std::vector<glm::dvec3> same(4, glm::dvec3(1, 2, 3));
  const std::vector<glm::dvec3> to = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const Similarity fit = procrustes(same, to);
  EXPECT_EQ(fit.scale, 1.0);
  EXPECT_NEAR(glm::length(fit.apply(same[0]) - glm::dvec3(0.25)), 0.0, 1e-12);
  EXPECT_THROW(procrustes(same, std::vector<glm::dvec3>(3)), std::invalid_argument);
  EXPECT_THROW(procrustes(std::vector<glm::dvec3>{}, std::vector<glm::dvec3>{}),
               std::invalid_argument);
}

}  // namespace
}  // namespace mocap::eval
