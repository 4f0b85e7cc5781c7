#pragma once
// Argument checks shared by the search methods. A wrong matrix or weight vector is a programming
// error in the caller, so they throw std::invalid_argument rather than mocap::InputError.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "posedb/search.hpp"

namespace mocap::posedb {

inline void check_matrix(const MatrixView& m, const std::string& what) {
  if (m.rows > std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument(what + ": more rows than a 32-bit neighbour index can address");
  }
  if (m.rows > 0 && (m.data == nullptr || m.dim <= 0)) {
    throw std::invalid_argument(what + ": a non-empty matrix needs data and a positive dimension");
  }
}

// k <= 0 asks for nothing; more than there are rows returns all rows.
inline std::size_t clamp_k(int k, std::size_t rows) {
  return k <= 0 ? 0 : std::min(static_cast<std::size_t>(k), rows);
}

// Throws unless every weight is finite and non-negative: a negative weight would silently break
// the ranking. Cheap next to any search, so every query is checked.
inline void check_weights(const float* weights, int dim) {
  if (weights == nullptr) return;
  for (int j = 0; j < dim; ++j) {
    if (!(std::isfinite(weights[j]) && weights[j] >= 0.0f)) {
      throw std::invalid_argument("search weights must be finite and non-negative");
    }
  }
}

inline void reject_weights(const float* weights, const std::string& method) {
  if (weights != nullptr) {
    throw std::invalid_argument(method + " cannot weight dimensions; use exact or cluster search");
  }
}

}  // namespace mocap::posedb
