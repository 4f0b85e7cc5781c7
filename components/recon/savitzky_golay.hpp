#pragma once
// Savitzky–Golay smoothing for offline use: each output sample is the value, at that sample, of
// the polynomial of degree `order` fitted by least squares to the `window` samples around it.
// It keeps peaks and polynomial trends up to that degree (a cubic passes through unchanged) while
// removing noise; defaults as in the issue: order 3, window 11.
//
// Ends: the first and last window/2 samples have no centred window. They take the window at that
// end of the sequence and evaluate its polynomial at their own position ("polynomial fit at the
// ends", scipy's mode "interp"), so every output comes from a full window and polynomials up to
// the order stay exact to the very ends; a shrinking window would fit fewer and fewer samples and
// let the noise through at the ends. A sequence shorter than the window is fitted as a whole by
// one polynomial of degree min(order, length − 1) (two samples or fewer come back unchanged).
//
// Samples are assumed equally spaced (frames of one rate).

#include <span>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

namespace mocap::recon {

class SavitzkyGolay {
 public:
  // Throws std::invalid_argument unless 0 <= order < window, window is odd and order <= 10 (beyond
  // that the fit is ill-conditioned and useless for smoothing anyway).
  explicit SavitzkyGolay(int order = 3, int window = 11);

  int order() const { return order_; }
  int window() const { return window_; }

  // The weights of the window's samples (oldest first) that give the fitted value at `position`
  // in the window: 0 … window − 1, window / 2 being the classic centred filter.
  std::span<const double> coefficients(int position) const;

  std::vector<float> smooth(std::span<const float> values) const;
  std::vector<glm::vec3> smooth(std::span<const glm::vec3> values) const;
  // Quaternions are first made to lie in one hemisphere along the sequence (each one negated
  // when it points away from the one before), then smoothed component-wise and renormalised.
  // Outputs may therefore be the negatives of the inputs: the same rotations. Component-wise
  // smoothing is a good approximation for the small changes within one window of a motion.
  std::vector<glm::quat> smooth(std::span<const glm::quat> values) const;

 private:
  int order_;
  int window_;
  std::vector<double> table_;  // window_ rows (output position) of window_ weights
};

// The least-squares weight table for `length` samples and a polynomial of degree `order`
// (< length): row p holds the weights giving the fitted value at sample p. Exposed for tests.
std::vector<double> savitzky_golay_table(int order, int length);

}  // namespace mocap::recon
