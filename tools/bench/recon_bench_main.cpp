// `mocap-bench-recon`: speed of the 2D-to-3D chain (scaler, matcher, temporal selection, smoothing)
// on one core, per configuration, on virtual-protocol input (held-out CMU clips seen by four
// cameras with 2 % 2D noise). Variants run interleaved in one process; medians are reported.

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "cli_args.hpp"
#include "core/input_error.hpp"
#include "eval/virtual_protocol.hpp"
#include "posedb/builder.hpp"
#include "posedb/database.hpp"

namespace {

using namespace mocap;
using Clock = std::chrono::steady_clock;

struct Variant {
  std::string name;
  recon::SequenceOptions options;
};

struct StageTimes {
  std::vector<double> match_us, select_us, total_pfs;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  cli::Args args("mocap-bench-recon --db DB [options]",
                 "Person-frames per second of the 2D-to-3D chain on one core, per configuration.");
  args.option("db", "FILE", "pose database (a million projections or more for the issue's target)")
      .option("mocap", "DIR", "cmu31 folder with splits.txt", "../shared/data/mocap/cmu31")
      .option("repeats", "N", "interleaved passes; medians are reported", "3")
      .option("clips", "N", "held-out clips used (0 = all)", "0");
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  try {
    if (!args.has("db")) throw InputError("--db", "required");
    const posedb::Database db = posedb::Database::open(args.get("db"));
    auto truth =
        eval::load_truth(posedb::split_files(args.get("mocap"), "heldout"), db.build_info().fps);
    if (const long n = args.integer("clips"); n > 0 && static_cast<std::size_t>(n) < truth.size())
      truth.resize(n);
    std::vector<std::vector<recon::BodyXyc>> inputs;
    std::size_t person_frames = 0;
    for (const auto& camera : eval::default_cameras(true)) {
      if (camera.yaw_deg != 0.0f) continue;  // one camera per family
      for (std::size_t s = 0; s < truth.size(); ++s) {
        inputs.push_back(eval::render(truth[s], camera, {}, {0.02f, 0.0f}, s).input);
        person_frames += inputs.back().size();
      }
    }
    const recon::FrameBones bones(db);
    std::vector<Variant> variants(4);
    variants[0] = {"nearest, no smoothing", {}};
    variants[0].options.selection = recon::Selection::nearest;
    variants[1] = {"greedy w=4 (paper), no smoothing", {}};
    variants[1].options.selection = recon::Selection::greedy;
    variants[2] = {"path (Viterbi), Savitzky-Golay", {}};
    variants[2].options.selection = recon::Selection::path;
    variants[2].options.smoothing = recon::Smoothing::savitzky_golay;
    variants[3] = {"path (Viterbi), 1-Euro", {}};
    variants[3].options.selection = recon::Selection::path;
    variants[3].options.smoothing = recon::Smoothing::one_euro;

    recon::Matcher matcher(db, recon::MatchOptions{});
    std::vector<StageTimes> times(variants.size());
    for (long pass = 0; pass < args.integer("repeats"); ++pass) {
      for (std::size_t v = 0; v < variants.size(); ++v) {
        double match_s = 0, select_s = 0;
        const auto start = Clock::now();
        for (const auto& sequence : inputs) {
          // The matcher alone, then the whole chain: the difference is selection and smoothing.
          const auto m0 = Clock::now();
          std::vector<recon::Candidate> candidates;
          for (const auto& frame : sequence) matcher.match(frame, candidates);
          const auto m1 = Clock::now();
          const auto poses =
              recon::reconstruct_sequence(matcher, bones, sequence, variants[v].options);
          const auto m2 = Clock::now();
          match_s += std::chrono::duration<double>(m1 - m0).count();
          select_s += std::chrono::duration<double>(m2 - m1).count() -
                      std::chrono::duration<double>(m1 - m0).count();
        }
        const double total = std::chrono::duration<double>(Clock::now() - start).count() - match_s;
        times[v].match_us.push_back(1e6 * match_s / static_cast<double>(person_frames));
        times[v].select_us.push_back(1e6 * select_s / static_cast<double>(person_frames));
        times[v].total_pfs.push_back(static_cast<double>(person_frames) / total);
      }
    }
    std::cout
        << "## 2D-to-3D chain on one core: " << person_frames << " person-frames (" << truth.size()
        << " held-out clips x 4 cameras, 2 % noise), database of " << db.projections().rows
        << " projections, k = 32, probe 16\n\n"
        << "| configuration | scaler + matcher µs | selection + smoothing µs | person-frames/s |\n"
        << "|---|---:|---:|---:|\n";
    for (std::size_t v = 0; v < variants.size(); ++v) {
      std::cout << "| " << variants[v].name << " | " << std::fixed << std::setprecision(0)
                << median(times[v].match_us) << " | " << median(times[v].select_us) << " | "
                << median(times[v].total_pfs) << " |\n";
    }
    std::cout << "\nMedians over " << args.get("repeats")
              << " interleaved passes; single thread.\n";
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-recon: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
