#pragma once
// Approximate search with FLANN (randomized kd-tree forest or hierarchical k-means tree). FLANN's
// headers stay in flann_search.cpp: they are heavy, and most users of this header never search.
// FLANN has no weighted metric, so queries with missing joints need exact or cluster search.

#include <cstdint>
#include <memory>

#include "posedb/search.hpp"

namespace mocap::posedb {

enum class FlannAlgorithm { kd_forest, kmeans_tree };

struct FlannOptions {
  FlannAlgorithm algorithm = FlannAlgorithm::kd_forest;
  int trees = 4;       // kd_forest: number of randomized trees
  int branching = 32;  // kmeans_tree: children per node
  int iterations = 7;  // kmeans_tree: k-means iterations when splitting a node
  int checks = 128;    // leaves examined per query: the speed / recall trade-off
  std::uint32_t seed = 1;
};

class FlannSearch final : public SearchIndex {
 public:
  // Builds the index over `data`, which must outlive it (FLANN keeps pointers to the rows).
  // Seeds the C library's rand(), which FLANN draws from, so that a build is reproducible.
  FlannSearch(MatrixView data, const FlannOptions& options);
  ~FlannSearch() override;
  FlannSearch(FlannSearch&&) noexcept;
  FlannSearch& operator=(FlannSearch&&) noexcept;

  std::string name() const override;
  // `weights` must be null.
  void search(const float* query, const float* weights, int k,
              std::vector<Neighbor>& out) const override;
  std::size_t memory_bytes() const override;

  // Not safe while another thread searches.
  void set_checks(int checks);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::posedb
