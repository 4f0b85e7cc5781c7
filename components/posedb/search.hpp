#pragma once
// The common interface of every k-nearest-neighbour method over the pose database: exact scan,
// clusters with representatives, FLANN and FAISS. All of them rank rows by squared Euclidean
// distance (L2²) and none of them owns the rows it searches.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mocap::posedb {

// A read-only, row-major matrix of float32 that someone else owns (usually a memory-mapped file).
struct MatrixView {
  const float* data = nullptr;
  std::size_t rows = 0;
  int dim = 0;

  const float* row(std::size_t i) const { return data + i * static_cast<std::size_t>(dim); }
  bool empty() const { return rows == 0; }
};

struct Neighbor {
  std::uint32_t index;  // row index in the matrix the index was built on
  float distance;       // squared (and, where weights apply, weighted) Euclidean distance
};

class SearchIndex {
 public:
  virtual ~SearchIndex() = default;

  // A short label with the settings, e.g. "clusters(k=2048,probe=4)", for logs and tables.
  virtual std::string name() const = 0;

  // Writes the min(k, rows) nearest rows to `query` into `out`, sorted by increasing distance
  // (ties by increasing index). `out` is cleared first; reusing it across calls avoids
  // allocation. `weights` (nullable, `dim` non-negative values) turns the metric into
  // sum_j w_j (q_j - r_j)²; a query value whose weight is 0 is never read, so a missing joint may
  // be NaN there. Methods whose supports_weights() is false reject non-null weights.
  // Safe to call from several threads at once.
  virtual void search(const float* query, const float* weights, int k,
                      std::vector<Neighbor>& out) const = 0;

  virtual bool supports_weights() const { return false; }

  // Bytes the index holds in addition to the matrix it views (a copy of the rows counts).
  virtual std::size_t memory_bytes() const { return 0; }
};

}  // namespace mocap::posedb
