#pragma once
// Compares the pose database's nearest-neighbour methods on one matrix: build time, index memory,
// single-thread query latency and recall against exact search, as a Markdown table.

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <vector>

#include "posedb/search.hpp"

namespace mocap::bench {

struct SearchBenchOptions {
  int k = 10;  // neighbours per query; recall@1 and recall@k are reported
  // Timing passes over the queries, interleaved across methods so that a busy spell of a shared
  // machine spreads over all of them; each figure is the median over passes.
  int repeats = 5;
  double seconds_per_method = 8.0;  // a slow method stops repeating once it has used this much

  std::vector<int> cluster_counts = {1024, 2048};
  std::vector<int> cluster_probes = {1, 4, 16, 64};
  std::size_t kmeans_sample = 100'000;

  bool flann_kd_forest = true;
  bool flann_kmeans_tree = true;
  int flann_trees = 4;
  std::vector<int> flann_checks = {32, 128, 512};

  bool faiss_flat = true;  // the FAISS methods are skipped without MOCAP_HAVE_FAISS
  bool faiss_ivf = true;
  int faiss_nlist = 1024;
  std::vector<int> faiss_nprobes = {1, 8, 32};
  bool faiss_hnsw = true;
  int hnsw_m = 32;
  std::vector<int> hnsw_ef_search = {16, 64, 256};

  int build_threads = 2;
  std::uint64_t seed = 1;
  std::ostream* log = nullptr;  // one line per step (e.g. &std::cerr); null for silence
};

// Runs every enabled method on `data` with both query sets and prints the table to `out`.
// Queries have data.dim values each.
void run_search_benchmark(const posedb::MatrixView& data,
                          const std::vector<std::vector<float>>& clean_queries,
                          const std::vector<std::vector<float>>& noisy_queries, std::ostream& out,
                          const SearchBenchOptions& options = {});

}  // namespace mocap::bench
