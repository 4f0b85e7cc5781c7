#include "multiview/view_geometry.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace mocap::multiview {

namespace {

glm::dvec3 row(const std::array<double, 12>& p, int r) {
  return {p[4 * r], p[4 * r + 1], p[4 * r + 2]};
}

}  // namespace

ViewGeometry ViewGeometry::from_krt(const glm::dmat3& K, const glm::dmat3& R, const glm::dvec3& t,
                                    int width, int height) {
  const glm::dmat3 m = K * R;
  const glm::dvec3 kt = K * t;
  std::array<double, 12> p{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) p[4 * r + c] = m[c][r];
    p[4 * r + 3] = kt[r];
  }
  return from_projection(p, width, height);
}

ViewGeometry ViewGeometry::from_projection(std::span<const double, 12> row_major, int width,
                                           int height) {
  if (width < 0 || height < 0) {
    throw std::invalid_argument("ViewGeometry: a negative image size");
  }
  std::array<double, 12> p{};
  for (int i = 0; i < 12; ++i) {
    if (!std::isfinite(row_major[i])) {
      throw std::invalid_argument("ViewGeometry: the projection matrix is not finite");
    }
    p[i] = row_major[i];
  }
  const glm::dvec3 m0 = row(p, 0), m1 = row(p, 1), m2 = row(p, 2);
  const double det = glm::dot(m0, glm::cross(m1, m2));
  const double scale = glm::length(m0) * glm::length(m1) * glm::length(m2);
  if (!(scale > 0.0) || std::abs(det) < 1e-12 * scale) {
    throw std::invalid_argument("ViewGeometry: the projection matrix is singular");
  }
  // A projection matrix is defined up to scale: fix it so that row 3 gives the depth, positive in
  // front of the camera (det(K R) > 0 for a right-handed camera frame).
  const double s = (det > 0.0 ? 1.0 : -1.0) / glm::length(m2);
  for (double& v : p) v *= s;
  ViewGeometry g = from_normalised(p);
  g.width_ = width;
  g.height_ = height;
  return g;
}

ViewGeometry ViewGeometry::from_normalised(const std::array<double, 12>& p) {
  ViewGeometry g;
  g.p_ = p;
  const glm::dvec3 m0 = row(p, 0), m1 = row(p, 1), m2 = row(p, 2);
  // Rows of K R with unit m2: m0 = fx r0 + s r1 + cx r2, m1 = fy r1 + cy r2.
  g.focal_ = 0.5 * (glm::length(glm::cross(m0, m2)) + glm::length(glm::cross(m1, m2)));
  glm::dmat3 m;  // GLM: m[column][row]
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[c][r] = p[4 * r + c];
  }
  g.inverse_ = glm::inverse(m);
  g.centre_ = -(g.inverse_ * glm::dvec3(p[3], p[7], p[11]));
  return g;
}

double ViewGeometry::depth(const glm::dvec3& w) const {
  return p_[8] * w.x + p_[9] * w.y + p_[10] * w.z + p_[11];
}

glm::dvec2 ViewGeometry::project(const glm::dvec3& w) const {
  const double z = depth(w);
  if (!(z > 0.0)) {
    return glm::dvec2(std::numeric_limits<double>::quiet_NaN());
  }
  return {(p_[0] * w.x + p_[1] * w.y + p_[2] * w.z + p_[3]) / z,
          (p_[4] * w.x + p_[5] * w.y + p_[6] * w.z + p_[7]) / z};
}

bool ViewGeometry::sees(const glm::dvec3& world) const {
  const glm::dvec2 p = project(world);
  if (!std::isfinite(p.x) || !std::isfinite(p.y)) return false;
  if (width_ <= 0 || height_ <= 0) return true;
  return p.x >= 0.0 && p.x < width_ && p.y >= 0.0 && p.y < height_;
}

glm::dvec3 ViewGeometry::ray(double x, double y) const {
  return glm::normalize(inverse_ * glm::dvec3(x, y, 1.0));
}

}  // namespace mocap::multiview
