#include "search_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include "posedb/cluster_search.hpp"
#include "posedb/exact_search.hpp"
#include "posedb/flann_search.hpp"
#include "posedb/kmeans.hpp"
#ifdef MOCAP_HAVE_FAISS
#include "posedb/faiss_search.hpp"
#endif

namespace mocap::bench {
namespace {

using posedb::MatrixView;
using posedb::Neighbor;
using posedb::SearchIndex;
using Clock = std::chrono::steady_clock;
using Queries = std::vector<std::vector<float>>;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

double percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(fraction * double(values.size() - 1) + 0.5);
  return values[std::min(rank, values.size() - 1)];
}

// The exact neighbours of every query of one set, and their label in the table.
struct QuerySet {
  std::string label;
  const Queries* queries;
  std::vector<std::vector<Neighbor>> truth;
};

// Figures of one method on one query set.
struct SetFigures {
  std::vector<double> p50_us, p95_us;  // one entry per timed pass
  double recall_1 = 0.0;
  double recall_k = 0.0;
};

// One row of the table: a built index with one setting of its query-time knob.
struct Variant {
  std::string method;
  std::string settings;
  double build_seconds = 0.0;
  std::size_t memory_bytes = 0;
  SearchIndex* index = nullptr;
  std::function<void()> configure;  // applies this row's knob to an index shared by several rows
  std::vector<SetFigures> sets;
  double seconds_used = 0.0;
  bool repeat = true;  // false: measured once, elsewhere
};

// Tie-tolerant recall: a returned neighbour counts if it is no farther than the exact one of the
// same rank limit, since a pose database has many equally distant rows.
bool within(const Neighbor& found, float limit) {
  return found.distance <= limit * (1.0f + 1e-5f) + 1e-7f;
}

void add_recall(const std::vector<Neighbor>& found, const std::vector<Neighbor>& truth,
                double& hits_1, double& hits_k) {
  if (truth.empty()) return;
  if (!found.empty() && within(found.front(), truth.front().distance)) hits_1 += 1.0;
  std::size_t hits = 0;
  for (const Neighbor& n : found) hits += within(n, truth.back().distance) ? 1 : 0;
  hits_k += double(std::min(hits, truth.size())) / double(truth.size());
}

class SearchBench {
 public:
  SearchBench(const MatrixView& data, const SearchBenchOptions& options)
      : data_(data), options_(options) {}

  void add_query_set(std::string label, const Queries& queries) {
    for (const auto& query : queries) {
      if (query.size() != static_cast<std::size_t>(data_.dim)) {
        throw std::invalid_argument("search benchmark: a " + label + " query has " +
                                    std::to_string(query.size()) + " values, the data " +
                                    std::to_string(data_.dim));
      }
    }
    if (!queries.empty()) sets_.push_back({std::move(label), &queries, {}});
  }

  void run(std::ostream& out) {
    add_exact();
    add_clusters();
    add_flann();
    add_faiss();
    measure();
    print(out);
  }

 private:
  void say(const std::string& line) const {
    if (options_.log) *options_.log << "[search-bench] " << line << std::endl;
  }

  SearchIndex* keep(std::unique_ptr<SearchIndex> index) {
    indexes_.push_back(std::move(index));
    return indexes_.back().get();
  }

  Variant& add_variant(std::string method, std::string settings, double build_seconds,
                       SearchIndex* index, std::function<void()> configure = {}) {
    Variant v;
    v.method = std::move(method);
    v.settings = std::move(settings);
    v.build_seconds = build_seconds;
    v.memory_bytes = index->memory_bytes();
    v.index = index;
    v.configure = std::move(configure);
    v.sets.resize(sets_.size());
    variants_.push_back(std::move(v));
    return variants_.back();
  }

  // Exact search makes the ground truth; that single pass is also its timing, because it is by
  // far the slowest method and repeating it would dominate the run.
  void add_exact() {
    say("exact search: ground truth for " + std::to_string(sets_.size()) + " query sets");
    auto* exact = keep(std::make_unique<posedb::ExactSearch>(data_));
    Variant& v = add_variant("exact", "-", 0.0, exact);
    for (std::size_t s = 0; s < sets_.size(); ++s) {
      std::vector<double> us;
      for (const auto& query : *sets_[s].queries) {
        const auto start = Clock::now();
        exact->search(query.data(), nullptr, options_.k, result_);
        us.push_back(seconds_since(start) * 1e6);
        sets_[s].truth.push_back(result_);
      }
      v.sets[s].p50_us.push_back(median(us));
      v.sets[s].p95_us.push_back(percentile(us, 0.95));
      v.sets[s].recall_1 = v.sets[s].recall_k = 1.0;
    }
    v.repeat = false;
  }

  void add_clusters() {
    for (const int clusters : options_.cluster_counts) {
      if (clusters < 1 || static_cast<std::size_t>(clusters) > data_.rows) continue;
      say("k-means: " + std::to_string(clusters) + " clusters");
      const auto start = Clock::now();
      posedb::KMeansOptions km;
      km.clusters = clusters;
      km.sample_size = options_.kmeans_sample;
      km.seed = options_.seed;
      km.threads = options_.build_threads;
      auto sorted = std::make_unique<SortedRows>();
      sorted->kmeans = posedb::kmeans(data_, km);
      sorted->order = posedb::group_by_cluster(sorted->kmeans.assignment, clusters);
      sorted->rows.reserve(data_.rows * static_cast<std::size_t>(data_.dim));
      for (const std::uint32_t row : sorted->order.permutation) {
        sorted->rows.insert(sorted->rows.end(), data_.row(row), data_.row(row) + data_.dim);
      }
      const double build = seconds_since(start);
      auto* index =
          static_cast<posedb::ClusterSearch*>(keep(std::make_unique<posedb::ClusterSearch>(
              MatrixView{sorted->rows.data(), data_.rows, data_.dim},
              sorted->kmeans.centroid_view(), sorted->order.cluster_begin, 1)));
      sorted_.push_back(std::move(sorted));
      for (const int probe : options_.cluster_probes) {
        add_variant("clusters", "k=" + std::to_string(clusters) + " probe=" + std::to_string(probe),
                    build, index, [index, probe] { index->set_probe(probe); });
      }
    }
  }

  void add_flann() {
    struct Tree {
      bool enabled;
      posedb::FlannAlgorithm algorithm;
      std::string method;
    };
    const Tree trees[] = {
        {options_.flann_kd_forest, posedb::FlannAlgorithm::kd_forest,
         "flann kd-forest(" + std::to_string(options_.flann_trees) + ")"},
        {options_.flann_kmeans_tree, posedb::FlannAlgorithm::kmeans_tree, "flann kmeans-tree(32)"}};
    for (const Tree& tree : trees) {
      if (!tree.enabled || options_.flann_checks.empty()) continue;
      say(tree.method + ": building");
      posedb::FlannOptions fo;
      fo.algorithm = tree.algorithm;
      fo.trees = options_.flann_trees;
      fo.seed = static_cast<std::uint32_t>(options_.seed);
      const auto start = Clock::now();
      auto* index =
          static_cast<posedb::FlannSearch*>(keep(std::make_unique<posedb::FlannSearch>(data_, fo)));
      const double build = seconds_since(start);
      for (const int checks : options_.flann_checks) {
        add_variant(tree.method, "checks=" + std::to_string(checks), build, index,
                    [index, checks] { index->set_checks(checks); });
      }
    }
  }

#ifdef MOCAP_HAVE_FAISS
  posedb::FaissSearch* build_faiss(const std::string& what, posedb::FaissOptions fo,
                                   double& seconds) {
    say(what + ": building");
    fo.build_threads = options_.build_threads;
    fo.seed = static_cast<int>(options_.seed);
    const auto start = Clock::now();
    auto* index =
        static_cast<posedb::FaissSearch*>(keep(std::make_unique<posedb::FaissSearch>(data_, fo)));
    seconds = seconds_since(start);
    return index;
  }

  void add_faiss() {
    double build = 0.0;
    if (options_.faiss_flat) {
      posedb::FaissOptions fo;
      fo.type = posedb::FaissIndexType::flat;
      auto* index = build_faiss("faiss flat", fo, build);
      add_variant("faiss flat", "-", build, index);
    }
    if (options_.faiss_ivf && !options_.faiss_nprobes.empty()) {
      posedb::FaissOptions fo;
      fo.type = posedb::FaissIndexType::ivf_flat;
      fo.nlist = options_.faiss_nlist;
      const std::string method = "faiss ivf-flat(" + std::to_string(fo.nlist) + ")";
      auto* index = build_faiss(method, fo, build);
      for (const int nprobe : options_.faiss_nprobes) {
        add_variant(method, "nprobe=" + std::to_string(nprobe), build, index,
                    [index, nprobe] { index->set_nprobe(nprobe); });
      }
    }
    if (options_.faiss_hnsw && !options_.hnsw_ef_search.empty()) {
      posedb::FaissOptions fo;
      fo.type = posedb::FaissIndexType::hnsw_flat;
      fo.hnsw_m = options_.hnsw_m;
      const std::string method = "faiss hnsw-flat(M=" + std::to_string(fo.hnsw_m) + ")";
      auto* index = build_faiss(method, fo, build);
      for (const int ef : options_.hnsw_ef_search) {
        add_variant(method, "efSearch=" + std::to_string(ef), build, index,
                    [index, ef] { index->set_ef_search(ef); });
      }
    }
    // Per-query latency is single-threaded: one OpenMP team per query only adds wake-ups.
    posedb::set_faiss_threads(1);
  }
#else
  void add_faiss() {
    if (options_.faiss_flat || options_.faiss_ivf || options_.faiss_hnsw) {
      say("FAISS methods skipped: built without MOCAP_WITH_FAISS");
    }
  }
#endif

  // One timed pass of a variant over one query set; the first pass also scores recall.
  void timed_pass(Variant& v, std::size_t s, bool score) {
    const QuerySet& set = sets_[s];
    std::vector<double> us;
    us.reserve(set.queries->size());
    double hits_1 = 0.0, hits_k = 0.0;
    for (std::size_t q = 0; q < set.queries->size(); ++q) {
      const auto start = Clock::now();
      v.index->search((*set.queries)[q].data(), nullptr, options_.k, result_);
      const double seconds = seconds_since(start);
      us.push_back(seconds * 1e6);
      v.seconds_used += seconds;
      if (score) add_recall(result_, set.truth[q], hits_1, hits_k);
    }
    SetFigures& figures = v.sets[s];
    figures.p50_us.push_back(median(us));
    figures.p95_us.push_back(percentile(us, 0.95));
    if (score) {
      figures.recall_1 = hits_1 / double(set.queries->size());
      figures.recall_k = hits_k / double(set.queries->size());
    }
  }

  void measure() {
    const int repeats = std::max(options_.repeats, 1);
    for (int pass = 0; pass < repeats; ++pass) {
      say("timing pass " + std::to_string(pass + 1) + " of " + std::to_string(repeats));
      for (Variant& v : variants_) {
        if (!v.repeat || (pass > 0 && v.seconds_used > options_.seconds_per_method)) continue;
        if (v.configure) v.configure();
        for (std::size_t s = 0; s < sets_.size(); ++s) timed_pass(v, s, pass == 0);
      }
    }
  }

  void print(std::ostream& out) const {
    out << "Search benchmark: " << data_.rows << " rows x " << data_.dim
        << " dims, k = " << options_.k
        << ", single-thread latency in microseconds (median over up to "
        << std::max(options_.repeats, 1)
        << " interleaved passes of each pass's p50 / p95), recall against exact search.\n\n";
    out << "| method | settings | build s | index MB |";
    for (const QuerySet& set : sets_) {
      out << ' ' << set.label << " p50 µs | " << set.label << " p95 µs | " << set.label << " R@1 | "
          << set.label << " R@" << options_.k << " |";
    }
    out << "\n|---|---|---:|---:|";
    for (std::size_t s = 0; s < sets_.size(); ++s) out << "---:|---:|---:|---:|";
    out << '\n';
    for (const Variant& v : variants_) print_row(out, v);
    out << "\nindex MB: memory beyond the rows the method searches (FAISS keeps its own copy, "
           "which "
           "counts; clusters view rows stored sorted by cluster, as in the database file).\n";
  }

  void print_row(std::ostream& out, const Variant& v) const {
    char cell[64];
    out << "| " << v.method << " | " << v.settings << " | ";
    std::snprintf(cell, sizeof cell, "%.2f | %.2f |", v.build_seconds,
                  double(v.memory_bytes) / (1024.0 * 1024.0));
    out << cell;
    for (const SetFigures& f : v.sets) {
      std::snprintf(cell, sizeof cell, " %.1f | %.1f | %.3f | %.3f |", median(f.p50_us),
                    median(f.p95_us), f.recall_1, f.recall_k);
      out << cell;
    }
    out << '\n';
  }

  // Rows sorted by k-means cluster, as the database file stores them.
  struct SortedRows {
    posedb::KMeansResult kmeans;
    posedb::ClusterOrder order;
    std::vector<float> rows;
  };

  MatrixView data_;
  const SearchBenchOptions& options_;
  std::vector<QuerySet> sets_;
  std::vector<std::unique_ptr<SearchIndex>> indexes_;
  std::vector<std::unique_ptr<SortedRows>> sorted_;
  std::vector<Variant> variants_;
  std::vector<Neighbor> result_;  // reused by every search, so timing excludes its allocation
};

}  // namespace

void run_search_benchmark(const posedb::MatrixView& data, const Queries& clean_queries,
                          const Queries& noisy_queries, std::ostream& out,
                          const SearchBenchOptions& options) {
  SearchBench bench(data, options);
  bench.add_query_set("clean", clean_queries);
  bench.add_query_set("noisy", noisy_queries);
  bench.run(out);
}

}  // namespace mocap::bench
