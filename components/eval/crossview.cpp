#include "eval/crossview.hpp"

#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace mocap::eval {
namespace {

constexpr int kRoot = index(Joint::root);

glm::dvec3 relative(const Body& b, int j) { return glm::dvec3(b[j]) - glm::dvec3(b[kRoot]); }

// Rodrigues' formula for a rotation by `angle` about unit `axis`.
glm::dvec3 rotate_about(const glm::dvec3& v, const glm::dvec3& axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.0 - c);
}

}  // namespace

Body to_world_root_relative(const Body& camera_root_relative, const glm::dmat3& camera_to_world) {
  Body out;
  const glm::dvec3 root = camera_to_world * glm::dvec3(camera_root_relative[kRoot]);
  for (int j = 0; j < kBodyJoints; ++j)
    out[j] = glm::vec3(camera_to_world * glm::dvec3(camera_root_relative[j]) - root);
  return out;
}

double vertical_alignment_angle(const Body& from, const Body& to, const glm::dvec3& up) {
  // Minimising Σ |R(θ) a − b|² over θ maximises Σ b·R(θ)a; with the horizontal parts a⊥, b⊥ this
  // is cos θ Σ a⊥·b⊥ + sin θ Σ (up × a⊥)·b⊥, maximal at θ = atan2(Σ up·(a⊥ × b⊥), Σ a⊥·b⊥).
  double c = 0.0, s = 0.0;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (j == kRoot) continue;
    glm::dvec3 a = relative(from, j), b = relative(to, j);
    a -= glm::dot(a, up) * up;
    b -= glm::dot(b, up) * up;
    c += glm::dot(a, b);
    s += glm::dot(up, glm::cross(a, b));
  }
  return std::atan2(s, c);
}

double crossview_distance(const Body& a, const Body& b, const glm::dvec3& up,
                          CrossViewAlignment alignment) {
  const glm::dvec3 axis = glm::normalize(up);
  const double angle =
      alignment == CrossViewAlignment::vertical_axis ? vertical_alignment_angle(a, b, axis) : 0.0;
  double sum = 0.0;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (j == kRoot) continue;
    sum += glm::distance(rotate_about(relative(a, j), axis, angle), relative(b, j));
  }
  return sum / (kBodyJoints - 1);
}

std::vector<CrossViewPair> crossview_pairs(std::span<const std::vector<std::optional<Body>>> views,
                                           const glm::dvec3& up, CrossViewAlignment alignment) {
  std::vector<CrossViewPair> out;
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (std::size_t k = i + 1; k < views.size(); ++k) {
      CrossViewPair pair{i, k, 0.0, 0.0};
      const std::size_t n = std::min(views[i].size(), views[k].size());
      for (std::size_t t = 0; t < n; ++t) {
        if (!views[i][t] || !views[k][t]) continue;
        pair.sum_m += crossview_distance(*views[i][t], *views[k][t], up, alignment);
        pair.frames += 1.0;
      }
      out.push_back(pair);
    }
  }
  return out;
}

void add_pairs(std::vector<CrossViewPair>& total, std::span<const CrossViewPair> more) {
  if (total.empty()) {
    total.assign(more.begin(), more.end());
    return;
  }
  for (std::size_t p = 0; p < total.size() && p < more.size(); ++p) {
    total[p].sum_m += more[p].sum_m;
    total[p].frames += more[p].frames;
  }
}

double mean_cm(std::span<const CrossViewPair> pairs) {
  double sum = 0.0, frames = 0.0;
  for (const auto& p : pairs) sum += p.sum_m, frames += p.frames;
  return frames > 0 ? 100.0 * sum / frames : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace mocap::eval
