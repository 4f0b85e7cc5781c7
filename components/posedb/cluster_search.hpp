#pragma once
// The paper's "clusters with representatives": rows are grouped by k-means cluster, a query is
// compared with every cluster centre, and only the rows of the `probe` nearest clusters are
// scanned. With probe = number of clusters it is exact.

#include <cstdint>
#include <span>

#include "posedb/search.hpp"

namespace mocap::posedb {

class ClusterSearch final : public SearchIndex {
 public:
  // `sorted_rows` holds the rows of cluster c at [cluster_begin[c], cluster_begin[c + 1]);
  // `centroids` has one row per cluster and the same dimension. All three must outlive the index:
  // it only views them, so construction is free. Throws std::invalid_argument on inconsistent
  // shapes or offsets.
  ClusterSearch(MatrixView sorted_rows, MatrixView centroids,
                std::span<const std::uint32_t> cluster_begin, int probe);

  std::string name() const override;
  void search(const float* query, const float* weights, int k,
              std::vector<Neighbor>& out) const override;
  bool supports_weights() const override { return true; }
  std::size_t memory_bytes() const override;

  int probe() const { return probe_; }
  // Not safe while another thread searches.
  void set_probe(int probe);
  int clusters() const { return static_cast<int>(centroids_.rows); }

 private:
  MatrixView rows_;
  MatrixView centroids_;
  std::span<const std::uint32_t> cluster_begin_;
  int probe_;
};

}  // namespace mocap::posedb
