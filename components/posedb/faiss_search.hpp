#pragma once
// Search with FAISS: exact flat scan, inverted file (IVF) and HNSW graph. Built only with the CMake
// option MOCAP_WITH_FAISS, in the library mocap_posedb_faiss (which defines MOCAP_HAVE_FAISS);
// FAISS's headers stay in faiss_search.cpp. FAISS has no weighted metric, so queries with missing
// joints need exact or cluster search. Every index keeps its own copy of the rows.

#include <cstdint>
#include <memory>

#include "posedb/search.hpp"

namespace mocap::posedb {

enum class FaissIndexType { flat, ivf_flat, hnsw_flat };

struct FaissOptions {
  FaissIndexType type = FaissIndexType::ivf_flat;
  int nlist = 1024;                    // ivf_flat: coarse clusters (clamped to the row count)
  int nprobe = 8;                      // ivf_flat: clusters scanned per query
  int train_points_per_centroid = 64;  // ivf_flat: training sample size, per cluster
  int train_iterations = 10;           // ivf_flat: k-means iterations of the coarse quantizer
  int hnsw_m = 32;                     // hnsw_flat: graph degree
  int ef_construction = 40;            // hnsw_flat: build-time beam width
  int ef_search = 64;                  // hnsw_flat: query-time beam width
  int build_threads = 2;               // OpenMP threads while building; restored afterwards
  int seed = 1;
};

class FaissSearch final : public SearchIndex {
 public:
  explicit FaissSearch(MatrixView data, const FaissOptions& options);
  ~FaissSearch() override;
  FaissSearch(FaissSearch&&) noexcept;
  FaissSearch& operator=(FaissSearch&&) noexcept;

  std::string name() const override;
  // `weights` must be null. Uses as many OpenMP threads as set_faiss_threads() allows.
  void search(const float* query, const float* weights, int k,
              std::vector<Neighbor>& out) const override;
  std::size_t memory_bytes() const override;

  // Query-time knobs; not safe while another thread searches.
  void set_nprobe(int nprobe);
  void set_ef_search(int ef_search);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Sets how many OpenMP threads FAISS may use from the calling thread on (omp_set_num_threads).
// Use 1 to measure single-query latency: a parallel region per query costs more than it saves.
void set_faiss_threads(int threads);

}  // namespace mocap::posedb
