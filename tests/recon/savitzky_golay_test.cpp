// Savitzky-Golay smoothing: the classic coefficient tables, exactness on polynomials (ends
// included), noise reduction, and quaternion sequences.

#include "recon/savitzky_golay.hpp"

#include <array>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/quaternion.hpp>

namespace mocap::recon {
namespace {

void expect_coefficients(const SavitzkyGolay& filter, int position, std::vector<double> numerators,
                         double denominator) {
  const std::span<const double> c = filter.coefficients(position);
  ASSERT_EQ(c.size(), numerators.size());
  for (std::size_t k = 0; k < c.size(); ++k) {
    EXPECT_NEAR(c[k], numerators[k] / denominator, 1e-12) << "coefficient " << k;
  }
}

// Savitzky and Golay (1964), table I; the quadratic and the cubic share the centred weights.
TEST(SavitzkyGolay, ClassicCentredCoefficients) {
  expect_coefficients(SavitzkyGolay(2, 5), 2, {-3, 12, 17, 12, -3}, 35);
  expect_coefficients(SavitzkyGolay(3, 5), 2, {-3, 12, 17, 12, -3}, 35);
  expect_coefficients(SavitzkyGolay(2, 7), 3, {-2, 3, 6, 7, 6, 3, -2}, 21);
  expect_coefficients(SavitzkyGolay(3, 11), 5, {-36, 9, 44, 69, 84, 89, 84, 69, 44, 9, -36}, 429);
  expect_coefficients(SavitzkyGolay(1, 5), 2, {1, 1, 1, 1, 1}, 5);  // a line: the moving average
}

// At the ends the straight-line fit over 5 samples evaluated at the first sample:
// intercept − 2·slope = Σ(1/5 − 2·(k−2)/10)·y_k = (3, 2, 1, 0, −1)/5.
TEST(SavitzkyGolay, EndCoefficientsOfALine) {
  expect_coefficients(SavitzkyGolay(1, 5), 0, {3, 2, 1, 0, -1}, 5);
  expect_coefficients(SavitzkyGolay(1, 5), 4, {-1, 0, 1, 2, 3}, 5);
}

TEST(SavitzkyGolay, EveryRowReproducesConstantsAndItsOwnPosition) {
  const SavitzkyGolay filter(3, 11);
  for (int p = 0; p < filter.window(); ++p) {
    const std::span<const double> c = filter.coefficients(p);
    EXPECT_NEAR(std::accumulate(c.begin(), c.end(), 0.0), 1.0, 1e-12) << p;
    double first_moment = 0.0;  // a ramp y_k = k comes out as p
    for (int k = 0; k < filter.window(); ++k) first_moment += c[k] * k;
    EXPECT_NEAR(first_moment, p, 1e-10) << p;
  }
}

double cubic(double t) { return 0.5 - 0.2 * t + 0.03 * t * t - 0.001 * t * t * t; }

// A polynomial of the filter's order is its own fit: unchanged everywhere, ends included.
TEST(SavitzkyGolay, CubicPassesThroughUnchanged) {
  const SavitzkyGolay filter;  // order 3, window 11
  for (int n : {40, 11, 7, 4}) {
    std::vector<float> y;
    for (int i = 0; i < n; ++i) y.push_back(static_cast<float>(cubic(i)));
    const std::vector<float> out = filter.smooth(y);
    ASSERT_EQ(out.size(), y.size());
    for (int i = 0; i < n; ++i)
      EXPECT_NEAR(out[i], y[i], 1e-4f * (1.0f + std::abs(y[i]))) << n << " " << i;
  }
}

TEST(SavitzkyGolay, ShortSequences) {
  const SavitzkyGolay filter;
  EXPECT_TRUE(filter.smooth(std::vector<float>{}).empty());
  EXPECT_EQ(filter.smooth(std::vector<float>{3.0f}), std::vector<float>{3.0f});
  const std::vector<float> two = filter.smooth(std::vector<float>{1.0f, 5.0f});
  EXPECT_NEAR(two[0], 1.0f, 1e-6f);
  EXPECT_NEAR(two[1], 5.0f, 1e-6f);
  // Six samples with order 3: a cubic fit over all six, so a spike is spread, not kept.
  const std::vector<float> spike = filter.smooth(std::vector<float>{0, 0, 0, 1, 0, 0});
  EXPECT_LT(spike[3], 1.0f);
  EXPECT_GT(spike[3], 0.0f);
}

TEST(SavitzkyGolay, RejectsBadParameters) {
  EXPECT_THROW(SavitzkyGolay(3, 10), std::invalid_argument);  // even
  EXPECT_THROW(SavitzkyGolay(3, 3), std::invalid_argument);   // window <= order
  EXPECT_THROW(SavitzkyGolay(-1, 5), std::invalid_argument);
  EXPECT_THROW(SavitzkyGolay(11, 31), std::invalid_argument);  // order too high
  EXPECT_NO_THROW(SavitzkyGolay(0, 1));
  EXPECT_THROW(SavitzkyGolay(2, 5).coefficients(5), std::out_of_range);
}

double rms(const std::vector<float>& a, const std::vector<double>& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(sum / static_cast<double>(a.size()));
}

TEST(SavitzkyGolay, ReducesNoise) {
  std::mt19937 rng(1);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  std::vector<double> truth;
  std::vector<float> noisy;
  for (int i = 0; i < 200; ++i) {
    truth.push_back(std::sin(i / 15.0));  // a slow movement at 30 fps (0.3 Hz)
    noisy.push_back(static_cast<float>(truth.back()) + noise(rng));
  }
  const std::vector<float> out = SavitzkyGolay().smooth(noisy);
  // 11-sample cubic: the noise power drops to about 0.21 (the sum of squared centred weights).
  EXPECT_LT(rms(out, truth), 0.6 * rms(noisy, truth));
}

TEST(SavitzkyGolay, Vec3IsPerCoordinate) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<glm::vec3> points(30);
  std::array<std::vector<float>, 3> coords;
  for (glm::vec3& p : points) {
    p = glm::vec3(u(rng), u(rng), u(rng));
    for (int c = 0; c < 3; ++c) coords[c].push_back(p[c]);
  }
  const SavitzkyGolay filter(2, 7);
  const std::vector<glm::vec3> out = filter.smooth(points);
  for (int c = 0; c < 3; ++c) {
    const std::vector<float> expected = filter.smooth(coords[c]);
    for (std::size_t i = 0; i < points.size(); ++i) EXPECT_FLOAT_EQ(out[i][c], expected[i]);
  }
}

// A steady turn (3° per frame) with the sign of every other quaternion flipped: the hemisphere
// is made consistent first, so the turn comes out as it went in, unit length.
TEST(SavitzkyGolay, QuaternionsKeepOneHemisphere) {
  const glm::vec3 axis = glm::normalize(glm::vec3(1, 2, 0.5f));
  std::vector<glm::quat> input;
  for (int i = 0; i < 50; ++i) {
    const glm::quat q = glm::angleAxis(glm::radians(3.0f * i), axis);
    input.push_back(i % 2 ? -q : q);
  }
  const std::vector<glm::quat> out = SavitzkyGolay().smooth(input);
  ASSERT_EQ(out.size(), input.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_NEAR(glm::length(out[i]), 1.0f, 1e-6f);
    EXPECT_NEAR(std::abs(glm::dot(out[i], input[i])), 1.0f, 1e-6f) << i;
    if (i > 0) {
      EXPECT_GT(glm::dot(out[i], out[i - 1]), 0.0f) << i;
    }
  }
}

TEST(SavitzkyGolay, QuaternionNoiseReduced) {
  std::mt19937 rng(4);
  std::normal_distribution<float> noise(0.0f, 0.03f);
  std::vector<glm::quat> truth, noisy;
  for (int i = 0; i < 120; ++i) {
    const glm::quat q = glm::angleAxis(0.6f * std::sin(i / 20.0f), glm::vec3(0, 1, 0));
    const glm::vec3 w(noise(rng), noise(rng), noise(rng));
    truth.push_back(q);
    noisy.push_back(glm::angleAxis(glm::length(w), glm::normalize(w)) * q);
  }
  const std::vector<glm::quat> out = SavitzkyGolay().smooth(noisy);
  double raw = 0.0, smoothed = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    raw += 1.0 - std::abs(glm::dot(noisy[i], truth[i]));  // ≈ angle²/8
    smoothed += 1.0 - std::abs(glm::dot(out[i], truth[i]));
  }
  EXPECT_LT(smoothed, 0.4 * raw);
}

}  // namespace
}  // namespace mocap::recon
