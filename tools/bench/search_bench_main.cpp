// `mocap-bench-search`: the search benchmark on synthetic pose-like data, so that it runs without
// a database. Poses of a body have few degrees of freedom, so the rows lie near a smooth
// low-dimensional manifold in 28 dimensions (14 joints x (x, y), values within about [-1, 1]):
// here a random smooth map of a `latent`-dimensional cube, with a little noise. Noisy queries add
// detector-like jitter to fresh draws.

#include <cmath>
#include <exception>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cli_args.hpp"
#include "core/input_error.hpp"
#include "search_bench.hpp"

namespace {

constexpr int kPoseDim = 28;

// x_j = 0.5 sin(a_j . z + b_j): smooth, bounded, and folded enough that no kd split is trivial.
class PoseManifold {
 public:
  PoseManifold(int latent_dims, std::mt19937& rng)
      : latent_(latent_dims), slope_(static_cast<std::size_t>(latent_dims) * kPoseDim) {
    std::normal_distribution<float> slope(0.0f, 1.2f);
    std::uniform_real_distribution<float> phase(0.0f, 6.2831853f);
    for (float& a : slope_) a = slope(rng);
    for (float& b : phase_) b = phase(rng);
  }

  // Appends one pose: a random latent point mapped to 28 values, plus `jitter` per value.
  void draw(float jitter, std::mt19937& rng, std::vector<float>& out) const {
    std::uniform_real_distribution<float> latent(-1.0f, 1.0f);
    std::normal_distribution<float> noise(0.0f, 1.0f);
    std::vector<float> z(static_cast<std::size_t>(latent_));
    for (float& v : z) v = latent(rng);
    for (int j = 0; j < kPoseDim; ++j) {
      float angle = phase_[j];
      for (int l = 0; l < latent_; ++l)
        angle += slope_[static_cast<std::size_t>(j) * latent_ + l] * z[l];
      out.push_back(0.5f * std::sin(angle) + kRowNoise * noise(rng) + jitter * noise(rng));
    }
  }

 private:
  static constexpr float kRowNoise = 0.005f;
  int latent_;
  std::vector<float> slope_;
  float phase_[kPoseDim];
};

std::vector<std::vector<float>> make_queries(const PoseManifold& poses, long count, float jitter,
                                             std::mt19937& rng) {
  std::vector<std::vector<float>> queries(static_cast<std::size_t>(count));
  for (auto& q : queries) poses.draw(jitter, rng, q);
  return queries;
}

std::vector<int> int_list(const std::string& text, const std::string& option) {
  std::vector<int> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      values.push_back(std::stoi(item));
    } catch (const std::exception&) {
      throw mocap::InputError("--" + option,
                              "expected a comma-separated list of integers, got '" + text + "'");
    }
  }
  return values;
}

mocap::cli::Args declare_options() {
  mocap::cli::Args args("mocap-bench-search [options]",
                        "Benchmarks exact, cluster, FLANN and FAISS search on synthetic poses.");
  args.option("rows", "N", "database rows", "200000")
      .option("queries", "N", "queries per set (clean and noisy)", "200")
      .option("latent", "N", "degrees of freedom of the synthetic poses", "8")
      .option("noise", "SIGMA", "jitter added to the noisy queries", "0.03")
      .option("k", "K", "neighbours per query", "10")
      .option("repeats", "N", "interleaved timing passes", "5")
      .option("clusters", "LIST", "k-means cluster counts", "1024,2048")
      .option("probes", "LIST", "clusters probed per query", "1,4,16,64")
      .option("checks", "LIST", "FLANN checks", "32,128,512")
      .option("nlist", "N", "FAISS IVF lists", "1024")
      .option("nprobes", "LIST", "FAISS IVF probes", "1,8,32")
      .option("hnsw-m", "M", "FAISS HNSW degree", "32")
      .option("ef", "LIST", "FAISS HNSW efSearch", "16,64,256")
      .option("seed", "N", "random seed", "1")
      .flag("no-flann-kmeans", "skip FLANN's hierarchical k-means tree")
      .flag("no-faiss", "skip every FAISS method")
      .flag("no-hnsw", "skip FAISS HNSW (its build is the slowest)");
  return args;
}

mocap::bench::SearchBenchOptions bench_options(const mocap::cli::Args& args) {
  mocap::bench::SearchBenchOptions o;
  o.k = static_cast<int>(args.integer("k"));
  o.repeats = static_cast<int>(args.integer("repeats"));
  o.cluster_counts = int_list(args.get("clusters"), "clusters");
  o.cluster_probes = int_list(args.get("probes"), "probes");
  o.flann_checks = int_list(args.get("checks"), "checks");
  o.flann_kmeans_tree = !args.has("no-flann-kmeans");
  o.faiss_nlist = static_cast<int>(args.integer("nlist"));
  o.faiss_nprobes = int_list(args.get("nprobes"), "nprobes");
  o.hnsw_m = static_cast<int>(args.integer("hnsw-m"));
  o.hnsw_ef_search = int_list(args.get("ef"), "ef");
  o.faiss_flat = o.faiss_ivf = o.faiss_hnsw = !args.has("no-faiss");
  o.faiss_hnsw = o.faiss_hnsw && !args.has("no-hnsw");
  o.seed = static_cast<std::uint64_t>(args.integer("seed"));
  o.log = &std::cerr;
  return o;
}

int run(int argc, char** argv) {
  mocap::cli::Args args = declare_options();
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  const mocap::bench::SearchBenchOptions options = bench_options(args);

  std::mt19937 rng(static_cast<std::uint32_t>(options.seed));
  const PoseManifold poses(static_cast<int>(args.integer("latent")), rng);
  const auto rows = static_cast<std::size_t>(args.integer("rows"));
  std::vector<float> data;
  data.reserve(rows * kPoseDim);
  for (std::size_t i = 0; i < rows; ++i) poses.draw(0.0f, rng, data);
  const long queries = args.integer("queries");
  const auto clean = make_queries(poses, queries, 0.0f, rng);
  const auto noisy = make_queries(poses, queries, static_cast<float>(args.number("noise")), rng);

  mocap::bench::run_search_benchmark({data.data(), rows, kPoseDim}, clean, noisy, std::cout,
                                     options);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
