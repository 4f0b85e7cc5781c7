#pragma once
// Brute force over every row: the reference every other method is measured against, and the only
// one that is exact for weighted queries without further thought.

#include "posedb/search.hpp"

namespace mocap::posedb {

class ExactSearch final : public SearchIndex {
 public:
  // `data` must outlive the index and have fewer than 2^32 rows.
  explicit ExactSearch(MatrixView data);

  std::string name() const override { return "exact"; }
  void search(const float* query, const float* weights, int k,
              std::vector<Neighbor>& out) const override;
  bool supports_weights() const override { return true; }

 private:
  MatrixView data_;
};

}  // namespace mocap::posedb
