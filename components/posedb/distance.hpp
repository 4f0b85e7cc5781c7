#pragma once
// Squared Euclidean distance kernels, plain C++ that GCC vectorises at -O3 with baseline SSE2.
//
// A single running float sum is a reduction GCC may not reorder without -ffast-math, so it would
// stay scalar; four independent lane sums are ordinary element-wise arithmetic that maps onto one
// SSE register. kFixedDim > 0 fixes the dimension at compile time (28 = 7 x 4 for the database),
// which drops the scalar tail loop; the lane loop is still kept rolled, because GCC 12 fully
// unrolls seven iterations into 28 scalar statements that its SLP vectoriser then fails to pack
// (measured: 2-3x slower per row).

namespace mocap::posedb {

inline constexpr int kDistanceLanes = 4;

template <int kFixedDim>
inline float squared_l2(const float* a, const float* b, int dim) {
  const int n = kFixedDim > 0 ? kFixedDim : dim;
  float lane[kDistanceLanes] = {};
  int j = 0;
#pragma GCC unroll 1
  for (; j + kDistanceLanes <= n; j += kDistanceLanes) {
    for (int l = 0; l < kDistanceLanes; ++l) {
      const float d = a[j + l] - b[j + l];
      lane[l] += d * d;
    }
  }
  float sum = (lane[0] + lane[2]) + (lane[1] + lane[3]);
  for (; j < n; ++j) {
    const float d = a[j] - b[j];
    sum += d * d;
  }
  return sum;
}

template <int kFixedDim>
inline float weighted_squared_l2(const float* a, const float* b, const float* w, int dim) {
  const int n = kFixedDim > 0 ? kFixedDim : dim;
  float lane[kDistanceLanes] = {};
  int j = 0;
#pragma GCC unroll 1
  for (; j + kDistanceLanes <= n; j += kDistanceLanes) {
    for (int l = 0; l < kDistanceLanes; ++l) {
      const float d = a[j + l] - b[j + l];
      lane[l] += w[j + l] * d * d;
    }
  }
  float sum = (lane[0] + lane[2]) + (lane[1] + lane[3]);
  for (; j < n; ++j) {
    const float d = a[j] - b[j];
    sum += w[j] * d * d;
  }
  return sum;
}

}  // namespace mocap::posedb
