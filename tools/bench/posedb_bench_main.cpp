// `mocap-bench-posedb`: the pose database on real mocap. Builds the database from the train split
// (build rate, size, the time to open it), then compares every search method on queries taken
// from the held-out subjects: clean, and with 2D noise.

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>

#include "cli_args.hpp"
#include "core/input_error.hpp"
#include "posedb/builder.hpp"
#include "posedb/database.hpp"
#include "search_bench.hpp"

namespace {

using namespace mocap;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Gaussian noise of `sigma` (a fraction of the 2D bounding-box height, which is 1 after
// normalisation) on every joint, the root included; then normalised again as a detection would be.
std::vector<float> with_noise(const float* row, float sigma, posedb::Scaling scaling,
                              std::mt19937& rng) {
  std::normal_distribution<float> noise(0.0f, sigma);
  std::array<glm::vec2, kBodyJoints> points;
  for (int j = 0; j < kBodyJoints - 1; ++j)
    points[j] = {row[2 * j] + noise(rng), row[2 * j + 1] + noise(rng)};
  points[index(Joint::root)] = {noise(rng), noise(rng)};
  posedb::PoseVector out;
  if (!posedb::normalize_pose(points, scaling, out)) return {row, row + posedb::kPoseDims};
  return {out.begin(), out.end()};
}

}  // namespace

int main(int argc, char** argv) {
  cli::Args args(
      "mocap-bench-posedb [options]",
      "Builds the pose database from the CMU train split and benchmarks its search methods on\n"
      "held-out queries (clean and noisy). Prints Markdown tables.");
  args.option("mocap", "DIR", "the cmu31 folder with splits.txt", "../shared/data/mocap/cmu31")
      .option("queries", "N", "queries per set", "1000")
      .option("noise", "SIGMA", "2D noise of the noisy set, fraction of the bounding-box height",
              "0.02")
      .option("repeats", "N", "timing passes (medians are reported)", "5")
      .option("out", "FILE", "where to write the database (removed afterwards unless --keep)",
              "/tmp/mocap-bench.mdb")
      .flag("keep", "keep the database file")
      .flag("quick", "fewer method settings");
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  try {
    const std::string folder = args.get("mocap");
    posedb::BuildOptions options;
    options.command = "mocap-bench-posedb";
    posedb::BuildReport report;

    auto t = Clock::now();
    const auto db_contents =
        posedb::build_database(posedb::split_files(folder, "train"), options, {}, report);
    const double build_s = seconds_since(t);
    t = Clock::now();
    posedb::write_database(db_contents, args.get("out"));
    const double write_s = seconds_since(t);
    t = Clock::now();
    const posedb::Database db = posedb::Database::open(args.get("out"));
    const double open_s = seconds_since(t);
    t = Clock::now();
    const posedb::Database db_fast = posedb::Database::open(args.get("out"), false);
    const double open_fast_s = seconds_since(t);

    const std::size_t rows = db.projections().rows;
    std::cout << "## Pose database build (CMU train split, " << db.clips().size() << " clips)\n\n"
              << "| frames | views | projections | clusters | build s | projections/s | write s | "
                 "file MB | open s (checksums) | open s (no checks) |\n"
              << "|---|---|---|---|---|---|---|---|---|---|\n"
              << std::fixed << std::setprecision(2) << "| " << db.frames().size() << " | "
              << db.views().size() << " | " << rows << " | " << db.centroids().rows << " | "
              << build_s << " | " << std::setprecision(0) << static_cast<double>(rows) / build_s
              << " | " << std::setprecision(2) << write_s << " | " << std::setprecision(1)
              << static_cast<double>(db.file_size()) / 1e6 << " | " << std::setprecision(3)
              << open_s << " | " << open_fast_s << " |\n\n";

    // Queries: held-out subjects through the same cameras, sampled at random.
    posedb::BuildReport heldout_report;
    posedb::BuildOptions heldout_options = options;
    heldout_options.clusters = 16;
    const auto heldout = posedb::build_database(posedb::split_files(folder, "heldout"),
                                                heldout_options, {}, heldout_report);
    std::mt19937 rng(7);
    const std::size_t heldout_rows = heldout.projection_records.size();
    std::vector<std::vector<float>> clean, noisy;
    const float sigma = static_cast<float>(args.number("noise"));
    for (long q = 0; q < args.integer("queries"); ++q) {
      const float* row = heldout.projections.data() + (rng() % heldout_rows) * posedb::kPoseDims;
      clean.emplace_back(row, row + posedb::kPoseDims);
      noisy.push_back(with_noise(row, sigma, options.scaling, rng));
    }
    std::cout << "Queries: " << clean.size()
              << " held-out projections (subjects 02, 05, 06, 07) clean, and the same with "
              << sigma * 100 << " % 2D noise.\n\n";

    bench::SearchBenchOptions bench;
    bench.repeats = static_cast<int>(args.integer("repeats"));
    bench.log = &std::cerr;
    if (args.has("quick")) {
      bench.cluster_counts = {1024};
      bench.flann_checks = {128};
      bench.faiss_nprobes = {8};
      bench.hnsw_ef_search = {64};
      bench.flann_kmeans_tree = false;
    }
    bench::run_search_benchmark(db.projections(), clean, noisy, std::cout, bench);
    if (!args.has("keep")) std::filesystem::remove(args.get("out"));
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-posedb: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
