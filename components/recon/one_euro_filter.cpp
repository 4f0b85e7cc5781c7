#include "recon/one_euro_filter.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <glm/geometric.hpp>

namespace mocap::recon {
namespace {

void check(const OneEuroParams& p) {
  if (!(p.min_cutoff > 0.0) || !(p.d_cutoff > 0.0) || !(p.beta >= 0.0)) {
    throw std::invalid_argument("1-Euro filter: needs min_cutoff > 0, d_cutoff > 0, beta >= 0");
  }
}

// Axis times angle of a unit quaternion with w >= 0 (a rotation of at most half a turn).
glm::vec3 rotation_vector(const glm::quat& r) {
  const glm::vec3 v(r.x, r.y, r.z);
  const float s = glm::length(v);
  const float angle = 2.0f * std::atan2(s, r.w);
  // For tiny s, angle/s tends to 2/w; dividing by s itself would lose all precision.
  const float scale = s > 1e-12f ? angle / s : 2.0f / r.w;
  return v * scale;
}

glm::quat from_rotation_vector(const glm::vec3& v) {
  const float angle = glm::length(v);
  // sin(angle/2)/angle by its series below 1e-4 rad, where the quotient would lose precision.
  const float scale = angle > 1e-4f ? std::sin(0.5f * angle) / angle : 0.5f - angle * angle / 48.0f;
  return glm::quat(std::cos(0.5f * angle), v * scale);
}

}  // namespace

double one_euro_alpha(double te_seconds, double cutoff_hz) {
  const double tau = 1.0 / (2.0 * std::numbers::pi * cutoff_hz);
  return 1.0 / (1.0 + tau / te_seconds);
}

namespace detail {

OneEuroClock::Step OneEuroClock::tick(double t_seconds) {
  if (!std::isfinite(t_seconds)) throw std::invalid_argument("1-Euro filter: non-finite time");
  if (started_ && t_seconds == t_previous_) return Step::repeat;
  if (!started_ || t_seconds < t_previous_) {
    started_ = true;
    t_previous_ = t_seconds;
    return Step::first;
  }
  te_ = t_seconds - t_previous_;
  t_previous_ = t_seconds;
  return Step::advance;
}

}  // namespace detail

OneEuroFilter::OneEuroFilter(OneEuroParams params) : params_(params) { check(params_); }

double OneEuroFilter::filter(double t_seconds, double x) {
  switch (clock_.tick(t_seconds)) {
    case detail::OneEuroClock::Step::first:
      x_hat_ = x;
      dx_hat_ = 0.0;
      return x_hat_;
    case detail::OneEuroClock::Step::repeat:
      return x_hat_;
    case detail::OneEuroClock::Step::advance:
      break;
  }
  const double te = clock_.te();
  const double dx = (x - x_hat_) / te;
  dx_hat_ += one_euro_alpha(te, params_.d_cutoff) * (dx - dx_hat_);
  const double cutoff = params_.min_cutoff + params_.beta * std::abs(dx_hat_);
  x_hat_ += one_euro_alpha(te, cutoff) * (x - x_hat_);
  return x_hat_;
}

OneEuroFilterVec3::OneEuroFilterVec3(OneEuroParams params) : params_(params) { check(params_); }

glm::vec3 OneEuroFilterVec3::filter(double t_seconds, const glm::vec3& x) {
  switch (clock_.tick(t_seconds)) {
    case detail::OneEuroClock::Step::first:
      x_hat_ = x;
      dx_hat_ = glm::vec3(0.0f);
      return x_hat_;
    case detail::OneEuroClock::Step::repeat:
      return x_hat_;
    case detail::OneEuroClock::Step::advance:
      break;
  }
  const double te = clock_.te();
  const glm::vec3 dx = (x - x_hat_) / static_cast<float>(te);
  dx_hat_ += static_cast<float>(one_euro_alpha(te, params_.d_cutoff)) * (dx - dx_hat_);
  const double cutoff = params_.min_cutoff + params_.beta * glm::length(dx_hat_);
  x_hat_ += static_cast<float>(one_euro_alpha(te, cutoff)) * (x - x_hat_);
  return x_hat_;
}

OneEuroFilterQuat::OneEuroFilterQuat(OneEuroParams params) : params_(params) { check(params_); }

glm::quat OneEuroFilterQuat::filter(double t_seconds, const glm::quat& q) {
  switch (clock_.tick(t_seconds)) {
    case detail::OneEuroClock::Step::first:
      x_hat_ = glm::normalize(q);
      omega_hat_ = glm::vec3(0.0f);
      return x_hat_;
    case detail::OneEuroClock::Step::repeat:
      return x_hat_;
    case detail::OneEuroClock::Step::advance:
      break;
  }
  const glm::quat target = glm::dot(x_hat_, q) < 0.0f ? -q : q;
  const glm::vec3 step = rotation_vector(glm::normalize(target) * glm::conjugate(x_hat_));
  const double te = clock_.te();
  const glm::vec3 omega = step / static_cast<float>(te);
  omega_hat_ += static_cast<float>(one_euro_alpha(te, params_.d_cutoff)) * (omega - omega_hat_);
  const double cutoff = params_.min_cutoff + params_.beta * glm::length(omega_hat_);
  const float alpha = static_cast<float>(one_euro_alpha(te, cutoff));
  x_hat_ = glm::normalize(from_rotation_vector(alpha * step) * x_hat_);
  return x_hat_;
}

}  // namespace mocap::recon
