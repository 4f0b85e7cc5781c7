#pragma once
// Assigns many points to the nearest of many centroids at once, as k-means needs for every
// iteration and for the final pass over the whole database (1.5M rows x thousands of centroids).
//
// Pairwise distances would spend most of their time summing across SSE lanes. Instead the
// centroids are repacked in panels of eight, dimension-major, and the kernel computes
// |c|²/2 - x.c for a tile of points against a whole panel: a small matrix product that GCC keeps
// in registers and vectorises across centroids. The point norm is constant per point, so it is
// not needed to pick the nearest centroid.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "posedb/search.hpp"

namespace mocap::posedb {

class NearestCentroid {
 public:
  explicit NearestCentroid(const MatrixView& centroids);

  // For points [begin, end): writes the nearest centroid's index to index[i - begin] and the
  // squared distance to it to distance[i - begin] (computed exactly, after the choice). Equal
  // scores go to the lower centroid index. Thread-safe.
  void assign(const MatrixView& points, std::size_t begin, std::size_t end, std::uint32_t* index,
              float* distance) const;

  std::size_t centroids() const { return centroids_; }

 private:
  void assign_tile(const float* const* tile_points, std::uint32_t* index) const;

  int dim_ = 0;
  std::size_t centroids_ = 0;
  std::size_t panels_ = 0;
  std::vector<float> packed_;     // panel p, dimension j, lane l at (p * dim + j) * width + l
  std::vector<float> half_norm_;  // |c|² / 2 per packed centroid; +inf for padding lanes
  std::vector<float> rows_;       // the centroids as given, for the exact distances
};

}  // namespace mocap::posedb
