#include "posedb/exact_search.hpp"

#include <algorithm>

#include "posedb/row_scan.hpp"
#include "posedb/search_checks.hpp"

namespace mocap::posedb {

ExactSearch::ExactSearch(MatrixView data) : data_(data) { check_matrix(data_, "exact search"); }

void ExactSearch::search(const float* query, const float* weights, int k,
                         std::vector<Neighbor>& out) const {
  check_weights(weights, data_.dim);
  TopK top(out, clamp_k(k, data_.rows));
  if (k <= 0) return;  // out is already empty
  scan_rows(data_, 0, data_.rows, mask_missing(query, weights, data_.dim), weights, top);
  top.finish();
}

}  // namespace mocap::posedb
