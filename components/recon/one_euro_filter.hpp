#pragma once
// The 1€ filter (Casiez, Roussel and Vogel, CHI 2012): a first-order low-pass filter whose cutoff
// rises with the signal's speed, so that it removes jitter when the signal is slow and lags little
// when it is fast. The online smoother of the method, with the paper's defaults (Yiannakides et
// al.: β = 0.4, fc_min = 1 Hz).
//
// Per sample, with te the time since the previous sample and x̂ the previous output:
//   α(fc)  = 1 / (1 + τ/te), τ = 1 / (2π fc)        smoothing factor of a cutoff fc
//   dx     = (x − x̂) / te                            as in the paper's listing (its reference code
//                                                      uses the previous raw sample instead)
//   dx̂    = dx̂ + α(d_cutoff) · (dx − dx̂)
//   cutoff = min_cutoff + β · |dx̂|
//   x̂     = x̂ + α(cutoff) · (x − x̂)
// The first sample after construction or reset() passes through unchanged with dx̂ = 0.
//
// Timestamps are seconds and may be irregular (te is measured per sample). A sample with the same
// time as the previous one changes nothing and returns the current output; a time earlier than
// the previous one (a new stream, a seek) restarts the filter at that sample. A non-finite time,
// or parameters outside min_cutoff > 0, d_cutoff > 0, β ≥ 0, throw std::invalid_argument.
//
// 3-vectors are filtered as one point: dx is a velocity vector and |dx̂| its length, so the three
// coordinates share one cutoff and the filter does not depend on the axes. Quaternions are
// filtered on the rotation group itself, see OneEuroFilterQuat.

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

namespace mocap::recon {

struct OneEuroParams {
  double min_cutoff = 1.0;  // fc_min, Hz: the cutoff at rest; lower removes more jitter
  double beta = 0.4;        // cutoff slope, Hz per (unit / s) of speed; higher lags less
  double d_cutoff = 1.0;    // Hz: cutoff of the low-pass filter on the speed estimate
};

// Smoothing factor of a first-order low-pass filter with cutoff `cutoff_hz`, samples `te_seconds`
// apart.
double one_euro_alpha(double te_seconds, double cutoff_hz);

namespace detail {

// Timing shared by the three filters: first sample, sample interval, repeated or backwards time.
class OneEuroClock {
 public:
  enum class Step { first, repeat, advance };
  // Classifies a sample at `t_seconds`; for `advance`, te() is the interval since the last one.
  Step tick(double t_seconds);
  double te() const { return te_; }
  void reset() { started_ = false; }

 private:
  bool started_ = false;
  double t_previous_ = 0.0;
  double te_ = 0.0;
};

}  // namespace detail

class OneEuroFilter {
 public:
  explicit OneEuroFilter(OneEuroParams params = {});
  double filter(double t_seconds, double x);
  void reset() { clock_.reset(); }
  double value() const { return x_hat_; }
  const OneEuroParams& params() const { return params_; }

 private:
  OneEuroParams params_;
  detail::OneEuroClock clock_;
  double x_hat_ = 0.0;
  double dx_hat_ = 0.0;
};

class OneEuroFilterVec3 {
 public:
  explicit OneEuroFilterVec3(OneEuroParams params = {});
  glm::vec3 filter(double t_seconds, const glm::vec3& x);
  void reset() { clock_.reset(); }
  glm::vec3 value() const { return x_hat_; }
  const OneEuroParams& params() const { return params_; }

 private:
  OneEuroParams params_;
  detail::OneEuroClock clock_;
  glm::vec3 x_hat_{0.0f};
  glm::vec3 dx_hat_{0.0f};
};

// Filters rotations on the rotation group rather than on quaternion components: the step from x̂
// towards the new sample q is the rotation r = q·x̂⁻¹ (q taken in x̂'s hemisphere, so r is the
// shorter way round, at most half a turn), the speed is r's rotation vector (axis × angle, in the
// fixed frame) divided by te, and the output is x̂ turned by the fraction α of r: slerp(x̂, q, α).
// This is the exact counterpart of the scalar filter: for rotations about one fixed axis it gives
// the scalar filter applied to the angle, in rad and rad/s, so β means the same for both. Filtering
// the four components and renormalising would only approximate it, and less well for large steps.
// The output is always unit length; its sign follows the first sample (each output is in the
// hemisphere of the one before).
class OneEuroFilterQuat {
 public:
  explicit OneEuroFilterQuat(OneEuroParams params = {});
  glm::quat filter(double t_seconds, const glm::quat& q);
  void reset() { clock_.reset(); }
  glm::quat value() const { return x_hat_; }
  const OneEuroParams& params() const { return params_; }

 private:
  OneEuroParams params_;
  detail::OneEuroClock clock_;
  glm::quat x_hat_{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 omega_hat_{0.0f};  // rad/s, fixed frame
};

}  // namespace mocap::recon
