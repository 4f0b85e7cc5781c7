#include "posedb/faiss_search.hpp"

#include <faiss/IndexFlat.h>
#include <faiss/IndexHNSW.h>
#include <faiss/IndexIVFFlat.h>
#include <omp.h>

#include <algorithm>
#include <stdexcept>

#include "posedb/search_checks.hpp"
#include "posedb/top_k.hpp"

namespace mocap::posedb {

namespace {

using FaissIndex = faiss::Index;
using FaissCount = faiss::Index::idx_t;

struct BuiltIndex {
  // Declared before `index`, which points to it, so that it is destroyed after it.
  std::unique_ptr<faiss::IndexFlatL2> quantizer;
  std::unique_ptr<FaissIndex> index;  // null for an empty matrix: FAISS cannot train on nothing
};

// Restores the caller's OpenMP thread count when the build is done, also on an exception.
class OmpThreadScope {
 public:
  explicit OmpThreadScope(int threads) : previous_(omp_get_max_threads()) {
    omp_set_num_threads(std::max(threads, 1));
  }
  ~OmpThreadScope() { omp_set_num_threads(previous_); }
  OmpThreadScope(const OmpThreadScope&) = delete;
  OmpThreadScope& operator=(const OmpThreadScope&) = delete;

 private:
  int previous_;
};

// `nlist` must not exceed the row count: FAISS's k-means refuses fewer rows than clusters.
BuiltIndex build_ivf(const MatrixView& data, const FaissOptions& o) {
  BuiltIndex built;
  built.quantizer = std::make_unique<faiss::IndexFlatL2>(data.dim);
  auto ivf = std::make_unique<faiss::IndexIVFFlat>(built.quantizer.get(), data.dim, o.nlist);
  // FAISS subsamples the training rows itself; fewer rows and iterations than its defaults keep
  // training short with the reference BLAS while costing little recall.
  ivf->cp.max_points_per_centroid = o.train_points_per_centroid;
  ivf->cp.niter = o.train_iterations;
  ivf->cp.seed = o.seed;
  ivf->train(static_cast<FaissCount>(data.rows), data.data);
  ivf->add(static_cast<FaissCount>(data.rows), data.data);
  built.index = std::move(ivf);
  return built;
}

BuiltIndex build_hnsw(const MatrixView& data, const FaissOptions& o) {
  auto hnsw = std::make_unique<faiss::IndexHNSWFlat>(data.dim, o.hnsw_m);
  hnsw->hnsw.efConstruction = o.ef_construction;
  hnsw->add(static_cast<FaissCount>(data.rows), data.data);
  return {nullptr, std::move(hnsw)};
}

BuiltIndex build_flat(const MatrixView& data) {
  auto flat = std::make_unique<faiss::IndexFlatL2>(data.dim);
  flat->add(static_cast<FaissCount>(data.rows), data.data);
  return {nullptr, std::move(flat)};
}

BuiltIndex build_index(const MatrixView& data, const FaissOptions& options) {
  if (data.empty()) return {};
  const OmpThreadScope threads(options.build_threads);
  switch (options.type) {
    case FaissIndexType::flat:
      return build_flat(data);
    case FaissIndexType::ivf_flat:
      return build_ivf(data, options);
    case FaissIndexType::hnsw_flat:
      return build_hnsw(data, options);
  }
  throw std::invalid_argument("FAISS search: unknown index type");
}

}  // namespace

struct FaissSearch::Impl {
  MatrixView data;
  FaissOptions options;
  BuiltIndex built;
};

FaissSearch::FaissSearch(MatrixView data, const FaissOptions& options)
    : impl_(std::make_unique<Impl>(Impl{data, options, {}})) {
  check_matrix(data, "FAISS search");
  set_nprobe(options.nprobe);  // rejects bad knobs before a long build
  set_ef_search(options.ef_search);
  impl_->options.nlist = static_cast<int>(
      std::min<std::size_t>(std::max(options.nlist, 1), std::max<std::size_t>(data.rows, 1)));
  impl_->built = build_index(data, impl_->options);
  set_nprobe(options.nprobe);  // again, now that there is an index to apply them to
  set_ef_search(options.ef_search);
}

FaissSearch::~FaissSearch() = default;
FaissSearch::FaissSearch(FaissSearch&&) noexcept = default;
FaissSearch& FaissSearch::operator=(FaissSearch&&) noexcept = default;

std::string FaissSearch::name() const {
  const FaissOptions& o = impl_->options;
  switch (o.type) {
    case FaissIndexType::flat:
      return "faiss-flat";
    case FaissIndexType::ivf_flat:
      return "faiss-ivf(nlist=" + std::to_string(o.nlist) + ",nprobe=" + std::to_string(o.nprobe) +
             ")";
    case FaissIndexType::hnsw_flat:
      return "faiss-hnsw(M=" + std::to_string(o.hnsw_m) + ",ef=" + std::to_string(o.ef_search) +
             ")";
  }
  return "faiss";
}

// The knobs are written into the index itself: FAISS 1.7.3's HNSW ignores the efSearch of a
// SearchParametersHNSW passed to search() (measured: recall and latency did not move).
void FaissSearch::set_nprobe(int nprobe) {
  if (nprobe < 1) throw std::invalid_argument("FAISS search: nprobe must be at least 1");
  impl_->options.nprobe = nprobe;
  if (auto* ivf = dynamic_cast<faiss::IndexIVF*>(impl_->built.index.get())) {
    ivf->nprobe = static_cast<std::size_t>(nprobe);
  }
}

void FaissSearch::set_ef_search(int ef_search) {
  if (ef_search < 1) throw std::invalid_argument("FAISS search: efSearch must be at least 1");
  impl_->options.ef_search = ef_search;
  if (auto* hnsw = dynamic_cast<faiss::IndexHNSW*>(impl_->built.index.get())) {
    hnsw->hnsw.efSearch = ef_search;
  }
}

std::size_t FaissSearch::memory_bytes() const {
  const FaissIndex* index = impl_->built.index.get();
  if (index == nullptr) return 0;
  const std::size_t vectors = static_cast<std::size_t>(index->ntotal) * index->d * sizeof(float);
  if (const auto* ivf = dynamic_cast<const faiss::IndexIVFFlat*>(index)) {
    const std::size_t ids = static_cast<std::size_t>(ivf->ntotal) * sizeof(FaissCount);
    const std::size_t centroids = ivf->nlist * ivf->d * sizeof(float);
    return vectors + ids + centroids;
  }
  if (const auto* hnsw = dynamic_cast<const faiss::IndexHNSW*>(index)) {
    const faiss::HNSW& graph = hnsw->hnsw;
    return vectors + graph.neighbors.size() * sizeof(faiss::HNSW::storage_idx_t) +
           graph.levels.size() * sizeof(int) + graph.offsets.size() * sizeof(std::size_t);
  }
  return vectors;
}

void FaissSearch::search(const float* query, const float* weights, int k,
                         std::vector<Neighbor>& out) const {
  reject_weights(weights, "FAISS search");
  const std::size_t wanted = clamp_k(k, impl_->data.rows);
  out.clear();
  if (wanted == 0 || !impl_->built.index) return;

  thread_local std::vector<float> distances;
  thread_local std::vector<FaissCount> labels;
  distances.resize(wanted);
  labels.resize(wanted);

  impl_->built.index->search(1, query, static_cast<FaissCount>(wanted), distances.data(),
                             labels.data());
  for (std::size_t i = 0; i < wanted; ++i) {
    if (labels[i] >= 0) out.push_back({static_cast<std::uint32_t>(labels[i]), distances[i]});
  }
  // FAISS orders ties arbitrarily; the common order breaks them by index.
  std::sort(out.begin(), out.end(), closer);
}

void set_faiss_threads(int threads) { omp_set_num_threads(std::max(threads, 1)); }

}  // namespace mocap::posedb
