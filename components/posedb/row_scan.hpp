#pragma once
// The brute-force inner loop shared by exact search (all rows) and cluster search (the rows of
// the probed clusters, and the centroids themselves).

#include <cstddef>

#include "posedb/search.hpp"
#include "posedb/top_k.hpp"

namespace mocap::posedb {

// Offers rows [begin, end) of `rows` to `top`, by squared L2 distance to `query`, weighted by
// `weights` when it is not null.
void scan_rows(const MatrixView& rows, std::size_t begin, std::size_t end, const float* query,
               const float* weights, TopK& top);

// Returns `query` when `weights` is null; otherwise a copy in a per-thread buffer (valid until the
// next call on the same thread) whose zero-weight values are 0, because a missing joint may be
// NaN and 0 * NaN would poison the whole distance.
const float* mask_missing(const float* query, const float* weights, int dim);

}  // namespace mocap::posedb
