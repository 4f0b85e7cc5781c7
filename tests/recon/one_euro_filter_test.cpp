// The 1-Euro filter against values computed by hand, and its behaviour on noisy signals.

#include "recon/one_euro_filter.hpp"

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/quaternion.hpp>

namespace mocap::recon {
namespace {

TEST(OneEuroAlpha, FirstOrderLowPass) {
  // τ = 1/(2π·1 Hz) = 0.159155 s; te = 0.1 s: α = 1/(1 + 1.59155) = 0.385870.
  EXPECT_NEAR(one_euro_alpha(0.1, 1.0), 0.385869545, 1e-9);
  // Same τ/te, same α.
  EXPECT_NEAR(one_euro_alpha(0.2, 0.5), one_euro_alpha(0.1, 1.0), 1e-12);
}

// Defaults β = 0.4, fc_min = 1 Hz, d_cutoff = 1 Hz, with irregular steps (0.1, 0.05, 0.2 s).
// Each line: α_d = α(te, 1), dx = (x − x̂)/te, dx̂ += α_d(dx − dx̂), fc = 1 + 0.4|dx̂|,
// α = α(te, fc), x̂ += α(x − x̂).
TEST(OneEuroFilter, HandComputedSteps) {
  OneEuroFilter f;
  EXPECT_EQ(f.filter(0.0, 0.0), 0.0);  // first sample passes through, dx̂ = 0
  // te 0.1: α_d 0.385870, dx 10, dx̂ 3.858695, fc 2.543478, α 0.615105, x̂ 0.615105.
  EXPECT_NEAR(f.filter(0.1, 1.0), 0.615105489, 1e-8);
  // te 0.05: α_d 0.239057, dx (1 − 0.615105)/0.05 = 7.697890, dx̂ 4.776483, fc 2.910593,
  // α 0.477640, x̂ 0.615105 + 0.477640 · 0.384895 = 0.798947.
  EXPECT_NEAR(f.filter(0.15, 1.0), 0.798946633, 1e-8);
  // te 0.2: α_d 0.556863, dx (0.5 − 0.798947)/0.2 = −1.494733, dx̂ 1.284276, fc 1.513711,
  // α 0.655432, x̂ 0.798947 − 0.655432 · 0.298947 = 0.603007.
  EXPECT_NEAR(f.filter(0.35, 0.5), 0.603007444, 1e-8);
  EXPECT_NEAR(f.value(), 0.603007444, 1e-8);
}

// β = 0: a plain low-pass filter with α = α(te, fc_min) whatever the speed.
TEST(OneEuroFilter, ZeroBetaIsFixedLowPass) {
  OneEuroFilter f({.min_cutoff = 1.0, .beta = 0.0, .d_cutoff = 1.0});
  f.filter(0.0, 0.0);
  const double a = 0.385869545;
  EXPECT_NEAR(f.filter(0.1, 1.0), a, 1e-8);
  EXPECT_NEAR(f.filter(0.2, 1.0), a + a * (1.0 - a), 1e-8);
}

TEST(OneEuroFilter, RepeatedTimeResetAndBackwardsTime) {
  OneEuroFilter f;
  f.filter(1.0, 0.0);
  const double after = f.filter(1.1, 1.0);
  EXPECT_EQ(f.filter(1.1, 50.0), after);  // same time: ignored
  EXPECT_EQ(f.filter(0.5, 7.0), 7.0);     // earlier time: restarts at that sample
  EXPECT_NEAR(f.filter(0.6, 8.0), 7.0 + 0.615105489, 1e-8);  // as a fresh filter, shifted by 7
  f.reset();
  EXPECT_EQ(f.filter(3.0, -2.0), -2.0);
  EXPECT_THROW(f.filter(NAN, 0.0), std::invalid_argument);
  EXPECT_THROW(OneEuroFilter({.min_cutoff = 0.0}), std::invalid_argument);
  EXPECT_THROW(OneEuroFilter({.beta = -1.0}), std::invalid_argument);
  EXPECT_THROW(OneEuroFilter({.d_cutoff = 0.0}), std::invalid_argument);
}

struct NoisyStep {
  std::vector<double> t;
  std::vector<double> clean;
  std::vector<double> noisy;
};

// 30 Hz with ±20 % jitter on the sample times; 0 until 2 s, then 1; Gaussian noise σ = 0.02.
NoisyStep noisy_step() {
  NoisyStep s;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::normal_distribution<double> noise(0.0, 0.02);
  double t = 0.0;
  for (int i = 0; i < 120; ++i) {
    s.t.push_back(t);
    s.clean.push_back(t < 2.0 ? 0.0 : 1.0);
    s.noisy.push_back(s.clean.back() + noise(rng));
    t += (1.0 + jitter(rng)) / 30.0;
  }
  return s;
}

double mean_abs_acceleration(const std::vector<double>& x, std::size_t first, std::size_t last) {
  double sum = 0.0;
  for (std::size_t i = first + 1; i + 1 < last; ++i)
    sum += std::abs(x[i + 1] - 2 * x[i] + x[i - 1]);
  return sum / static_cast<double>(last - first - 2);
}

TEST(OneEuroFilter, ReducesJitterAndFollowsAStep) {
  const NoisyStep s = noisy_step();
  OneEuroFilter f;
  std::vector<double> out;
  for (std::size_t i = 0; i < s.t.size(); ++i) out.push_back(f.filter(s.t[i], s.noisy[i]));
  std::size_t step = 0;
  while (s.t[step] < 2.0) ++step;
  // Jitter at rest (second half of the flat part) drops to well under half.
  const std::size_t rest = step / 2;
  EXPECT_LT(mean_abs_acceleration(out, rest, step),
            0.4 * mean_abs_acceleration(s.noisy, rest, step));
  // After the step the output gets there: within 5 % of the step 0.5 s later and stays close.
  for (std::size_t i = step; i < s.t.size(); ++i) {
    if (s.t[i] >= s.t[step] + 0.5) {
      EXPECT_NEAR(out[i], 1.0, 0.05) << "t " << s.t[i];
    }
  }
  // β makes it faster than the plain low-pass filter at fc_min (β = 0).
  OneEuroFilter slow({.min_cutoff = 1.0, .beta = 0.0, .d_cutoff = 1.0});
  double slow_at_150ms = 0.0, fast_at_150ms = 0.0;
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    const double v = slow.filter(s.t[i], s.noisy[i]);
    if (s.t[i] >= s.t[step] + 0.15 && slow_at_150ms == 0.0) {
      slow_at_150ms = v;
      fast_at_150ms = out[i];
    }
  }
  EXPECT_GT(fast_at_150ms, slow_at_150ms + 0.2);
}

// A 3-vector is one point: along one axis it is exactly the scalar filter.
TEST(OneEuroFilterVec3, AlongOneAxisMatchesScalar) {
  const NoisyStep s = noisy_step();
  OneEuroFilter scalar;
  OneEuroFilterVec3 vector;
  const glm::vec3 axis = glm::normalize(glm::vec3(1, 2, 2));
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    const double expected = scalar.filter(s.t[i], s.noisy[i]);
    const glm::vec3 got = vector.filter(s.t[i], static_cast<float>(s.noisy[i]) * axis);
    EXPECT_NEAR(glm::dot(got, axis), expected, 1e-5) << i;
    EXPECT_NEAR(glm::length(got - glm::dot(got, axis) * axis), 0.0f, 1e-5f) << i;
  }
}

// The three coordinates share one cutoff: the filter does not depend on the axes.
TEST(OneEuroFilterVec3, RotatingTheInputRotatesTheOutput) {
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  const glm::quat turn = glm::angleAxis(1.0f, glm::normalize(glm::vec3(1, -1, 2)));
  OneEuroFilterVec3 a, b;
  for (int i = 0; i < 60; ++i) {
    const double t = i / 30.0;
    const glm::vec3 x(std::sin(t) + noise(rng), std::cos(2 * t) + noise(rng), noise(rng));
    const glm::vec3 fa = a.filter(t, x);
    const glm::vec3 fb = b.filter(t, turn * x);
    EXPECT_NEAR(glm::distance(turn * fa, fb), 0.0f, 1e-5f) << i;
  }
}

// Rotations about one fixed axis: the quaternion filter is the scalar filter on the angle.
TEST(OneEuroFilterQuat, FixedAxisMatchesScalarOnAngle) {
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0.0, 0.05);
  const glm::vec3 axis = glm::normalize(glm::vec3(0.3f, 1.0f, -0.2f));
  OneEuroFilter scalar;
  OneEuroFilterQuat rotation;
  for (int i = 0; i < 90; ++i) {
    const double t = i / 30.0 + (i % 3) * 0.004;                // slightly irregular
    const double angle = 1.5 * std::sin(2.0 * t) + noise(rng);  // up to ±1.5 rad and fast
    const double expected = scalar.filter(t, angle);
    const glm::quat q = rotation.filter(t, glm::angleAxis(static_cast<float>(angle), axis));
    EXPECT_NEAR(glm::length(q), 1.0f, 1e-6f);
    const glm::quat want = glm::angleAxis(static_cast<float>(expected), axis);
    EXPECT_NEAR(std::abs(glm::dot(q, want)), 1.0f, 1e-6f) << i;
  }
}

// q and −q are one rotation: flipping the signs of the input changes nothing (up to sign).
TEST(OneEuroFilterQuat, SignOfTheInputDoesNotMatter) {
  OneEuroFilterQuat plain, flipped;
  for (int i = 0; i < 40; ++i) {
    const double t = i / 25.0;
    const glm::quat q = glm::angleAxis(static_cast<float>(0.1 * i), glm::vec3(0, 0, 1)) *
                        glm::angleAxis(0.5f, glm::vec3(1, 0, 0));
    const glm::quat a = plain.filter(t, q);
    const glm::quat b = flipped.filter(t, i % 2 ? -q : q);
    EXPECT_NEAR(std::abs(glm::dot(a, b)), 1.0f, 1e-6f) << i;
    EXPECT_GT(glm::dot(a, b), 0.0f) << "outputs stay in one hemisphere";
  }
}

// A half-turn-sized step is taken the shorter way and with the same fraction as a scalar.
TEST(OneEuroFilterQuat, LargeStepAndHandValue) {
  OneEuroFilterQuat f({.min_cutoff = 1.0, .beta = 0.0, .d_cutoff = 1.0});
  const glm::vec3 y(0, 1, 0);
  f.filter(0.0, glm::quat(1, 0, 0, 0));
  // β = 0: α(0.1 s, 1 Hz) = 0.385870 of a 3 rad turn.
  const glm::quat q = f.filter(0.1, glm::angleAxis(3.0f, y));
  EXPECT_NEAR(std::abs(glm::dot(q, glm::angleAxis(3.0f * 0.385869545f, y))), 1.0f, 1e-6f);
  // 3.5 rad one way is 2.78 rad the other way: the filter turns the shorter way (negative).
  OneEuroFilterQuat g({.min_cutoff = 1.0, .beta = 0.0, .d_cutoff = 1.0});
  g.filter(0.0, glm::quat(1, 0, 0, 0));
  const glm::quat r = g.filter(0.1, glm::angleAxis(3.5f, y));
  const float shorter = 3.5f - 2.0f * std::numbers::pi_v<float>;
  EXPECT_NEAR(std::abs(glm::dot(r, glm::angleAxis(shorter * 0.385869545f, y))), 1.0f, 1e-6f);
}

TEST(OneEuroFilterQuat, ReducesJitter) {
  std::mt19937 rng(21);
  std::normal_distribution<float> noise(0.0f, 0.03f);
  const glm::quat rest = glm::angleAxis(0.8f, glm::normalize(glm::vec3(1, 1, 0)));
  OneEuroFilterQuat f;
  double raw_error = 0.0, filtered_error = 0.0;
  for (int i = 0; i < 120; ++i) {
    const glm::quat wobble =
        glm::angleAxis(glm::length(glm::vec3(noise(rng), noise(rng), noise(rng))),
                       glm::normalize(glm::vec3(noise(rng), noise(rng), noise(rng))));
    const glm::quat q = wobble * rest;
    const glm::quat out = f.filter(i / 30.0, q);
    if (i < 30) continue;  // let it settle
    raw_error += 2.0 * std::acos(std::min(1.0f, std::abs(glm::dot(q, rest))));
    filtered_error += 2.0 * std::acos(std::min(1.0f, std::abs(glm::dot(out, rest))));
  }
  EXPECT_LT(filtered_error, 0.5 * raw_error);
}

}  // namespace
}  // namespace mocap::recon
