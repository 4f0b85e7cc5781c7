#pragma once
// k-means clustering of the pose database for the "clusters with representatives" search:
// k-means++ seeding and Lloyd iterations on a random sample, then one assignment of every row
// to its nearest centroid. Deterministic for a given seed, whatever the thread count.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "posedb/search.hpp"

namespace mocap::posedb {

struct KMeansOptions {
  int clusters = 2048;
  std::size_t sample_size = 100'000;  // rows the centroids are trained on; all rows if fewer
  int iterations = 10;                // Lloyd iterations on the sample (stops early if stable)
  std::uint64_t seed = 1;
  int threads = 2;  // for the Lloyd assignments and the final pass
  // Called on the calling thread with the fraction done, in [0, 1]; may be empty.
  std::function<void(double fraction)> progress;
};

struct KMeansResult {
  int dim = 0;
  std::vector<float> centroids;           // clusters() x dim, row-major
  std::vector<std::uint32_t> assignment;  // the cluster of every input row
  double inertia = 0.0;  // sum over all rows of the squared distance to its centroid

  int clusters() const { return dim > 0 ? static_cast<int>(centroids.size() / dim) : 0; }
  MatrixView centroid_view() const {
    return {centroids.data(), static_cast<std::size_t>(clusters()), dim};
  }
};

// Clusters `data` into min(options.clusters, rows) clusters (none for an empty matrix).
// Throws std::invalid_argument for clusters < 1 on a non-empty matrix.
KMeansResult kmeans(const MatrixView& data, const KMeansOptions& options);

// Sum over rows of the squared distance to the centroid `assignment` gives them.
double inertia(const MatrixView& data, const MatrixView& centroids,
               std::span<const std::uint32_t> assignment);

// How to store rows sorted by cluster: sorted row i is input row permutation[i], and cluster c
// occupies sorted rows [cluster_begin[c], cluster_begin[c + 1]). Rows keep their input order
// within a cluster.
struct ClusterOrder {
  std::vector<std::uint32_t> permutation;
  std::vector<std::uint32_t> cluster_begin;  // clusters + 1 offsets
};

ClusterOrder group_by_cluster(std::span<const std::uint32_t> assignment, int clusters);

}  // namespace mocap::posedb
