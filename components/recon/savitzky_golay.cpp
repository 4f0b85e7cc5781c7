#include "recon/savitzky_golay.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

namespace mocap::recon {
namespace {

constexpr int kMaxOrder = 10;

// Replaces a symmetric positive definite G (n × n, row-major) by its Cholesky factor L in the
// lower triangle (G = L·Lᵀ). n is at most 11 here: no pivoting or blocking needed.
void cholesky_factor(std::vector<double>& g, int n) {
  for (int col = 0; col < n; ++col) {
    double diagonal = g[col * n + col];
    for (int k = 0; k < col; ++k) diagonal -= g[col * n + k] * g[col * n + k];
    g[col * n + col] = std::sqrt(diagonal);
    for (int row = col + 1; row < n; ++row) {
      double v = g[row * n + col];
      for (int k = 0; k < col; ++k) v -= g[row * n + k] * g[col * n + k];
      g[row * n + col] = v / g[col * n + col];
    }
  }
}

// Solves L·Lᵀ·y = e in place (y holds e on entry).
void cholesky_solve(const std::vector<double>& l, int n, std::vector<double>& y) {
  for (int row = 0; row < n; ++row) {  // L·z = e
    for (int k = 0; k < row; ++k) y[row] -= l[row * n + k] * y[k];
    y[row] /= l[row * n + row];
  }
  for (int row = n - 1; row >= 0; --row) {  // Lᵀ·y = z
    for (int k = row + 1; k < n; ++k) y[row] -= l[k * n + row] * y[k];
    y[row] /= l[row * n + row];
  }
}

// Applies the weight table to every sample; each output takes the window that is centred on it,
// or the first or last window near the ends. Sums in double: Acc is the double counterpart of T.
template <typename Acc, typename T>
std::vector<T> apply_table(std::span<const T> values, const std::vector<double>& table,
                           int length) {
  const int n = static_cast<int>(values.size());
  std::vector<T> out(values.size());
  for (int i = 0; i < n; ++i) {
    const int start = std::clamp(i - length / 2, 0, n - length);
    const double* weights = table.data() + static_cast<std::size_t>(i - start) * length;
    Acc sum(0.0);
    for (int k = 0; k < length; ++k) sum += weights[k] * Acc(values[start + k]);
    out[i] = T(sum);
  }
  return out;
}

}  // namespace

std::vector<double> savitzky_golay_table(int order, int length) {
  if (order < 0 || length <= order) {
    throw std::invalid_argument("savitzky_golay_table: needs 0 <= order < length");
  }
  // Positions centred and scaled into [-1, 1] keep the normal equations well conditioned.
  const double centre = 0.5 * (length - 1);
  const double scale = std::max(centre, 1.0);
  const int terms = order + 1;
  std::vector<double> powers(static_cast<std::size_t>(length) * terms);  // A: x_k^a
  for (int k = 0; k < length; ++k) {
    double p = 1.0;
    for (int a = 0; a < terms; ++a, p *= (k - centre) / scale) powers[k * terms + a] = p;
  }
  std::vector<double> gram(static_cast<std::size_t>(terms) * terms, 0.0);  // AᵀA
  for (int a = 0; a < terms; ++a) {
    for (int b = 0; b < terms; ++b) {
      for (int k = 0; k < length; ++k)
        gram[a * terms + b] += powers[k * terms + a] * powers[k * terms + b];
    }
  }
  cholesky_factor(gram, terms);
  // The fitted value at position p is e_pᵀ (AᵀA)⁻¹ Aᵀ v with e_p = (x_p^a): weights A·(AᵀA)⁻¹·e_p.
  std::vector<double> table(static_cast<std::size_t>(length) * length);
  std::vector<double> y(terms);
  for (int p = 0; p < length; ++p) {
    std::copy_n(powers.begin() + p * terms, terms, y.begin());
    cholesky_solve(gram, terms, y);
    for (int k = 0; k < length; ++k) {
      double w = 0.0;
      for (int a = 0; a < terms; ++a) w += powers[k * terms + a] * y[a];
      table[p * length + k] = w;
    }
  }
  return table;
}

SavitzkyGolay::SavitzkyGolay(int order, int window) : order_(order), window_(window) {
  if (order < 0 || order > kMaxOrder || window <= order || window % 2 == 0) {
    throw std::invalid_argument("Savitzky-Golay: needs an odd window > order and 0 <= order <= " +
                                std::to_string(kMaxOrder) + " (got order " + std::to_string(order) +
                                ", window " + std::to_string(window) + ")");
  }
  table_ = savitzky_golay_table(order_, window_);
}

std::span<const double> SavitzkyGolay::coefficients(int position) const {
  if (position < 0 || position >= window_) {
    throw std::out_of_range("Savitzky-Golay: position outside the window");
  }
  return std::span<const double>(table_).subspan(static_cast<std::size_t>(position) * window_,
                                                 window_);
}

namespace {

// A sequence at least as long as the window uses the filter's own table; a shorter one is fitted
// as a whole, with a table made for its length.
template <typename Acc, typename T>
std::vector<T> smooth_sequence(std::span<const T> values, const std::vector<double>& table,
                               int order, int window) {
  const int n = static_cast<int>(values.size());
  if (n == 0) return {};
  if (n >= window) return apply_table<Acc>(values, table, window);
  return apply_table<Acc>(values, savitzky_golay_table(std::min(order, n - 1), n), n);
}

}  // namespace

std::vector<float> SavitzkyGolay::smooth(std::span<const float> values) const {
  return smooth_sequence<double>(values, table_, order_, window_);
}

std::vector<glm::vec3> SavitzkyGolay::smooth(std::span<const glm::vec3> values) const {
  return smooth_sequence<glm::dvec3>(values, table_, order_, window_);
}

std::vector<glm::quat> SavitzkyGolay::smooth(std::span<const glm::quat> values) const {
  std::vector<glm::vec4> components(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    const glm::quat& q = values[i];
    components[i] = glm::vec4(q.x, q.y, q.z, q.w);
    if (i > 0 && glm::dot(components[i], components[i - 1]) < 0.0f) components[i] = -components[i];
  }
  const std::vector<glm::vec4> smoothed =
      smooth_sequence<glm::dvec4>(std::span<const glm::vec4>(components), table_, order_, window_);
  std::vector<glm::quat> out(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    // A smoothed vector near zero would mean the window spans opposite rotations: keep the input.
    const glm::vec4& c = glm::length(smoothed[i]) > 1e-6f ? smoothed[i] : components[i];
    out[i] = glm::normalize(glm::quat(c.w, c.x, c.y, c.z));
  }
  return out;
}

}  // namespace mocap::recon
