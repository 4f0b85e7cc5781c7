#include "fit/ground_estimation.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>

namespace mocap::fit {
namespace {

// Adds `value` to a ring of at most `capacity` samples.
void push_bounded(std::vector<glm::dvec3>& ring, std::size_t& next, std::size_t capacity,
                  const glm::dvec3& value) {
  if (ring.size() < capacity) {
    ring.push_back(value);
    return;
  }
  ring[next] = value;
  next = (next + 1) % capacity;
}

double median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The unit eigenvector of the smallest eigenvalue of the symmetric `m` nearest `guess`, by inverse
// iteration; nullopt when the smallest eigenvalue is not separated from the next one.
std::optional<glm::dvec3> least_spread_direction(const glm::dmat3& m, glm::dvec3 guess) {
  const double scale = m[0][0] + m[1][1] + m[2][2];
  if (!(scale > 0)) return std::nullopt;
  const glm::dmat3 shifted = m + glm::dmat3(1e-9 * scale);
  if (std::abs(glm::determinant(shifted)) < 1e-18 * scale * scale * scale) return std::nullopt;
  const glm::dmat3 inverse = glm::inverse(shifted);
  for (int i = 0; i < 50; ++i) guess = glm::normalize(inverse * guess);
  // The spread along it must be clearly the smallest: compare with the other two directions.
  const double along = glm::dot(guess, m * guess);
  const double across = 0.5 * (scale - along);  // the mean of the other two eigenvalues
  if (!(along < 0.25 * across)) return std::nullopt;
  return guess;
}

}  // namespace

GroundEstimator::GroundEstimator(GroundEstimationOptions options) : options_(options) {}

void GroundEstimator::add(const Body& joints, std::array<bool, 2> contact) {
  const glm::dvec3 root(joints[index(Joint::root)]), neck(joints[index(Joint::neck)]);
  const glm::dvec3 trunk = neck - root;
  const double length = glm::length(trunk);
  if (!std::isfinite(length) || length < 1e-3) return;
  push_bounded(ups_, next_up_, options_.max_samples, trunk / length);
  const glm::dvec3 hips =
      glm::dvec3(joints[index(Joint::left_hip)]) - glm::dvec3(joints[index(Joint::right_hip)]);
  if (const double width = glm::length(hips); std::isfinite(width) && width > 1e-3)
    push_bounded(hips_, next_hip_, options_.max_samples, hips / width);
  for (std::size_t f = 0; f < kFeet.size(); ++f) {
    const glm::dvec3 ankle(joints[static_cast<std::size_t>(kFeet[f])]);
    if (contact[f] && std::isfinite(glm::dot(ankle, ankle)))
      push_bounded(ankles_, next_ankle_, options_.max_samples, ankle);
  }
}

std::optional<GroundEstimate> GroundEstimator::estimate() const {
  if (ups_.size() < options_.min_bodies || ankles_.size() < options_.min_contacts)
    return std::nullopt;
  glm::dvec3 sum(0.0);
  for (const auto& u : ups_) sum += u;
  if (glm::length(sum) < 1e-6) return std::nullopt;
  const glm::dvec3 upright = glm::normalize(sum);
  // The spread of the contacts (their covariance) and of the hip lines, in square metres.
  glm::dvec3 mean(0.0);
  for (const auto& p : ankles_) mean += p;
  mean /= static_cast<double>(ankles_.size());
  glm::dmat3 spread(0.0);
  for (const auto& p : ankles_) spread += glm::outerProduct(p - mean, p - mean);
  spread /= static_cast<double>(ankles_.size());
  if (!hips_.empty()) {
    glm::dmat3 hips(0.0);
    for (const auto& h : hips_) hips += glm::outerProduct(h, h);
    const double w = options_.hip_line_weight_m;
    spread += hips * (w * w / static_cast<double>(hips_.size()));
  }
  GroundEstimate out;
  glm::dvec3 up = upright;
  if (auto normal = least_spread_direction(spread, upright)) {
    if (glm::dot(*normal, upright) < 0) *normal = -*normal;
    const double tilt = std::acos(std::clamp(glm::dot(*normal, upright), -1.0, 1.0));
    if (tilt <= glm::radians(options_.max_tilt_from_upright_deg)) {
      up = *normal;
      out.normal_from_contacts = true;
    }
  }
  std::vector<double> heights;
  heights.reserve(ankles_.size());
  for (const auto& p : ankles_) heights.push_back(glm::dot(p, up));
  // On the plane dot(up, x) + offset = 0; a contact ankle is `clearance` above it.
  out.plane.normal = up;
  out.plane.offset = options_.ankle_clearance_m - median(std::move(heights));
  out.bodies = ups_.size();
  out.contacts = ankles_.size();
  return out;
}

}  // namespace mocap::fit
