#include "posedb/cluster_search.hpp"

#include <stdexcept>

#include "posedb/row_scan.hpp"
#include "posedb/search_checks.hpp"

namespace mocap::posedb {
namespace {

void check_layout(const MatrixView& rows, const MatrixView& centroids,
                  std::span<const std::uint32_t> cluster_begin) {
  check_matrix(rows, "cluster search rows");
  check_matrix(centroids, "cluster search centroids");
  if (cluster_begin.size() != centroids.rows + 1) {
    throw std::invalid_argument("cluster search: need one begin offset per cluster plus the end");
  }
  if (centroids.rows > 0 && rows.rows > 0 && centroids.dim != rows.dim) {
    throw std::invalid_argument("cluster search: centroids and rows differ in dimension");
  }
  if (cluster_begin.front() != 0 || cluster_begin.back() != rows.rows) {
    throw std::invalid_argument("cluster search: offsets must start at 0 and end at the row count");
  }
  for (std::size_t c = 0; c + 1 < cluster_begin.size(); ++c) {
    if (cluster_begin[c] > cluster_begin[c + 1]) {
      throw std::invalid_argument("cluster search: offsets must not decrease");
    }
  }
}

}  // namespace

ClusterSearch::ClusterSearch(MatrixView sorted_rows, MatrixView centroids,
                             std::span<const std::uint32_t> cluster_begin, int probe)
    : rows_(sorted_rows), centroids_(centroids), cluster_begin_(cluster_begin), probe_(probe) {
  check_layout(rows_, centroids_, cluster_begin_);
  set_probe(probe);
}

std::string ClusterSearch::name() const {
  return "clusters(k=" + std::to_string(centroids_.rows) + ",probe=" + std::to_string(probe_) + ")";
}

void ClusterSearch::set_probe(int probe) {
  if (probe < 1) throw std::invalid_argument("cluster search: probe must be at least 1");
  probe_ = probe;
}

std::size_t ClusterSearch::memory_bytes() const {
  // The centroids and offsets are views too, but they exist only for this method.
  return centroids_.rows * static_cast<std::size_t>(centroids_.dim) * sizeof(float) +
         cluster_begin_.size_bytes();
}

void ClusterSearch::search(const float* query, const float* weights, int k,
                           std::vector<Neighbor>& out) const {
  check_weights(weights, rows_.dim);
  TopK top(out, clamp_k(k, rows_.rows));
  if (rows_.rows == 0 || k <= 0) {
    top.finish();
    return;
  }
  const float* q = mask_missing(query, weights, rows_.dim);

  // The representatives are ranked with the same metric as the rows, so a weighted query also
  // picks clusters by its visible joints only.
  thread_local std::vector<Neighbor> nearest_clusters;
  TopK top_clusters(nearest_clusters, clamp_k(probe_, centroids_.rows));
  scan_rows(centroids_, 0, centroids_.rows, q, weights, top_clusters);
  top_clusters.finish();

  // Nearest cluster first: its rows tighten the bound early, so later clusters offer fewer rows.
  for (const Neighbor& cluster : nearest_clusters) {
    scan_rows(rows_, cluster_begin_[cluster.index], cluster_begin_[cluster.index + 1], q, weights,
              top);
  }
  top.finish();
}

}  // namespace mocap::posedb
