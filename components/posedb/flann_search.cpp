#include "posedb/flann_search.hpp"

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_index.h>
#include <flann/algorithms/kmeans_index.h>
#include <flann/util/random.h>

#include <algorithm>
#include <stdexcept>

#include "posedb/search_checks.hpp"
#include "posedb/top_k.hpp"

namespace mocap::posedb {

using FlannIndex = flann::NNIndex<flann::L2<float>>;

struct FlannSearch::Impl {
  MatrixView data;
  FlannOptions options;
  std::unique_ptr<FlannIndex> index;  // null for an empty matrix: FLANN cannot build on no rows
};

namespace {

// FLANN's matrices take non-const pointers but only read the dataset and the queries.
flann::Matrix<float> as_flann(const float* data, std::size_t rows, int dim) {
  return {const_cast<float*>(data), rows, static_cast<std::size_t>(dim)};
}

std::unique_ptr<FlannIndex> build_index(const MatrixView& data, const FlannOptions& options) {
  flann::seed_random(options.seed);
  const flann::Matrix<float> points = as_flann(data.data, data.rows, data.dim);
  std::unique_ptr<FlannIndex> index;
  if (options.algorithm == FlannAlgorithm::kd_forest) {
    index = std::make_unique<flann::KDTreeIndex<flann::L2<float>>>(
        points, flann::KDTreeIndexParams(options.trees));
  } else {
    index = std::make_unique<flann::KMeansIndex<flann::L2<float>>>(
        points, flann::KMeansIndexParams(options.branching, options.iterations,
                                         flann::FLANN_CENTERS_KMEANSPP));
  }
  index->buildIndex();
  return index;
}

}  // namespace

FlannSearch::FlannSearch(MatrixView data, const FlannOptions& options)
    : impl_(std::make_unique<Impl>(Impl{data, options, nullptr})) {
  check_matrix(data, "FLANN search");
  set_checks(options.checks);
  if (!data.empty()) impl_->index = build_index(data, options);
}

FlannSearch::~FlannSearch() = default;
FlannSearch::FlannSearch(FlannSearch&&) noexcept = default;
FlannSearch& FlannSearch::operator=(FlannSearch&&) noexcept = default;

std::string FlannSearch::name() const {
  const FlannOptions& o = impl_->options;
  const std::string checks = ",checks=" + std::to_string(o.checks) + ")";
  if (o.algorithm == FlannAlgorithm::kd_forest) {
    return "flann-kd(trees=" + std::to_string(o.trees) + checks;
  }
  return "flann-kmeans(branching=" + std::to_string(o.branching) + checks;
}

void FlannSearch::set_checks(int checks) {
  if (checks < 1) throw std::invalid_argument("FLANN search: checks must be at least 1");
  impl_->options.checks = checks;
}

std::size_t FlannSearch::memory_bytes() const {
  return impl_->index ? static_cast<std::size_t>(impl_->index->usedMemory()) : 0;
}

void FlannSearch::search(const float* query, const float* weights, int k,
                         std::vector<Neighbor>& out) const {
  reject_weights(weights, "FLANN search");
  const std::size_t wanted = clamp_k(k, impl_->data.rows);
  out.clear();
  if (wanted == 0 || !impl_->index) return;

  thread_local std::vector<std::size_t> indices;
  thread_local std::vector<float> distances;
  indices.resize(wanted);
  distances.resize(wanted);
  flann::Matrix<std::size_t> index_matrix(indices.data(), 1, wanted);
  flann::Matrix<float> distance_matrix(distances.data(), 1, wanted);
  const int found =
      impl_->index->knnSearch(as_flann(query, 1, impl_->data.dim), index_matrix, distance_matrix,
                              wanted, flann::SearchParams(impl_->options.checks));

  for (int i = 0; i < found; ++i) {
    out.push_back({static_cast<std::uint32_t>(indices[i]), distances[i]});
  }
  // FLANN sorts by distance only; the common order also breaks ties by index.
  std::sort(out.begin(), out.end(), closer);
}

}  // namespace mocap::posedb
