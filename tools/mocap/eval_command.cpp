// `mocap eval virtual | humaneva`: the evaluation protocols of ../shared/docs/EVALUATION.md.

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "eval/virtual_protocol.hpp"
#include "eval_report.hpp"
#include "posedb/builder.hpp"
#include "posedb/database.hpp"
#include "progress_bar.hpp"

namespace mocap::cli {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// One configuration of the method, compared side by side with the others in one run.
struct Config {
  std::string name;
  std::string description;
  const posedb::Database* db;
  recon::MatchOptions match;
  recon::SequenceOptions sequence;
};

std::vector<std::string> split_files(const std::string& folder, const std::string& split) {
  std::ifstream list(fs::path(folder) / "splits.txt");
  if (!list)
    throw InputError(folder,
                     "no splits.txt here: give the cmu31 folder of the shared data with --mocap");
  std::vector<std::string> files;
  std::string which, file;
  while (list >> which >> file) {
    if (which == split) files.push_back((fs::path(folder) / file).string());
  }
  return files;
}

// The paper's database: the same train clips seen only by the level 1.5 m camera, 30 yaws.
std::string build_paper_database(const std::string& mocap, const std::string& path) {
  posedb::BuildOptions options;
  options.views.heights_m = {1.5f};
  options.command = "mocap eval virtual (paper database: yaw-only views at 1.5 m)";
  posedb::BuildReport report;
  const auto contents = posedb::build_database(split_files(mocap, "train"), options, {}, report);
  posedb::write_database(contents, path);
  return path;
}

struct Job {
  std::size_t config, camera, condition, sequence;
};

// Runs every (configuration, camera, condition, sequence) on `threads` threads; one matcher per
// thread and configuration (matchers keep scratch space).
std::vector<eval::Scores> run_jobs(const std::vector<Config>& configs,
                                   const std::vector<eval::VirtualCamera>& cameras,
                                   const std::vector<eval::Condition>& conditions,
                                   const std::vector<eval::TruthSequence>& truth,
                                   const std::vector<std::unique_ptr<recon::FrameBones>>& bones,
                                   int threads, ProgressBar& bar) {
  std::vector<Job> jobs;
  for (std::size_t c = 0; c < configs.size(); ++c)
    for (std::size_t k = 0; k < cameras.size(); ++k)
      for (std::size_t n = 0; n < conditions.size(); ++n)
        for (std::size_t s = 0; s < truth.size(); ++s) jobs.push_back({c, k, n, s});
  std::vector<eval::Scores> results(jobs.size());
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex progress;
  auto work = [&] {
    std::vector<std::unique_ptr<recon::Matcher>> matchers;
    for (const auto& c : configs)
      matchers.push_back(std::make_unique<recon::Matcher>(*c.db, c.match));
    for (std::size_t i; (i = next++) < jobs.size();) {
      const Job& j = jobs[i];
      const std::uint64_t seed = 1000003ull * j.sequence + 1009ull * j.camera +
                                 j.condition;  // same input for every config
      const auto rendered =
          eval::render(truth[j.sequence], cameras[j.camera], {}, conditions[j.condition], seed);
      const auto poses = recon::reconstruct_sequence(*matchers[j.config], *bones[j.config],
                                                     rendered.input, configs[j.config].sequence);
      results[i] = eval::score(poses, rendered.truth_camera);
      std::lock_guard lock(progress);
      bar.update("evaluate", static_cast<double>(++done) / static_cast<double>(jobs.size()));
    }
  };
  std::vector<std::jthread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  pool.clear();
  // Sum the sequences of each (config, camera, condition).
  std::vector<eval::Scores> summed(configs.size() * cameras.size() * conditions.size());
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const Job& j = jobs[i];
    summed[(j.config * cameras.size() + j.camera) * conditions.size() + j.condition].add(
        results[i]);
  }
  return summed;
}

json scores_json(const eval::Scores& s) {
  return {{"mpjpe_mm", s.mpjpe()},
          {"pa_mpjpe_mm", s.pa_mpjpe()},
          {"accel_mm_per_frame2", s.accel()},
          {"jitter_mm_per_frame2", s.jitter()},
          {"coverage", s.coverage()},
          {"frames", s.frames}};
}

void print_row(const std::string& name, const std::string& what, const eval::Scores& s) {
  std::cout << "| " << name << " | " << what << " | " << std::fixed << std::setprecision(1)
            << s.mpjpe() << " | " << s.pa_mpjpe() << " | " << s.accel() << " | " << s.jitter()
            << " | " << std::setprecision(3) << s.coverage() << " |\n";
}

std::vector<Config> make_configs(const posedb::Database& full, const posedb::Database& paper,
                                 double fps) {
  recon::SequenceOptions base;
  base.fps = fps;
  std::vector<Config> configs;
  Config paper_config{
      "paper", "yaw-only views at 1.5 m, clusters, greedy w = 4, no smoothing", &paper, {}, base};
  paper_config.sequence.selection = recon::Selection::greedy;
  configs.push_back(paper_config);
  Config nn{
      "per-frame NN", "all views, nearest neighbour per frame, no smoothing", &full, {}, base};
  nn.sequence.selection = recon::Selection::nearest;
  configs.push_back(nn);
  Config greedy{"greedy", "all views, greedy w = 4, no smoothing", &full, {}, base};
  greedy.sequence.selection = recon::Selection::greedy;
  configs.push_back(greedy);
  Config path_sg{"full: path + SG",
                 "all views, Viterbi path over candidates, Savitzky-Golay (3, 11)",
                 &full,
                 {},
                 base};
  path_sg.sequence.selection = recon::Selection::path;
  path_sg.sequence.smoothing = recon::Smoothing::savitzky_golay;
  configs.push_back(path_sg);
  Config path_euro{"full live: path + 1-Euro",
                   "all views, Viterbi path, 1-Euro (beta 0.4, fc_min 1)",
                   &full,
                   {},
                   base};
  path_euro.sequence.selection = recon::Selection::path;
  path_euro.sequence.smoothing = recon::Smoothing::one_euro;
  configs.push_back(path_euro);
  return configs;
}

int virtual_protocol(int argc, char** argv) {
  Args args(
      "mocap eval virtual --db DB [options]",
      "The paper's virtual-video protocol on the held-out CMU subjects: cameras at several yaws, "
      "heights and\n"
      "pitches, 2D noise and joint drop-out; MPJPE, PA-MPJPE, acceleration error and jitter per "
      "configuration,\n"
      "noise level and camera family. Prints Markdown tables and writes every number as JSON.");
  args.option("db", "FILE",
              "database built from the train split (mocap db build ... --split train)")
      .option("paper-db", "FILE",
              "the paper's yaw-only 1.5 m database (built from the train split when absent)")
      .option("mocap", "DIR", "cmu31 folder with splits.txt", "../shared/data/mocap/cmu31")
      .option("json", "FILE", "where to write all numbers", "eval_virtual.json")
      .option("threads", "N", "worker threads", "2")
      .option("clips", "N", "use only the first N held-out clips (0 = all)", "0")
      .flag("quick", "2 yaws per camera family and 2 noise levels");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("db")) throw InputError("--db", "required: a database built from the train split");
  const auto started = std::chrono::steady_clock::now();
  const posedb::Database full = posedb::Database::open(args.get("db"));
  const std::string mocap = args.get("mocap");
  std::string paper_path = args.get("paper-db");
  const bool temporary_paper = paper_path.empty();
  if (temporary_paper) {
    paper_path =
        (fs::temp_directory_path() / ("mocap-paper-" + std::to_string(::getpid()) + ".mdb"))
            .string();
    std::cerr << "building the paper's yaw-only database in " << paper_path << "\n";
    build_paper_database(mocap, paper_path);
  }
  const posedb::Database paper = posedb::Database::open(paper_path);
  if (temporary_paper) fs::remove(paper_path);  // the mapping stays valid

  auto truth = eval::load_truth(split_files(mocap, "heldout"), full.build_info().fps);
  if (const long n = args.integer("clips"); n > 0 && static_cast<std::size_t>(n) < truth.size())
    truth.resize(n);
  const auto cameras = eval::default_cameras(args.has("quick"));
  const auto conditions = eval::default_conditions(args.has("quick"));
  const auto configs = make_configs(full, paper, full.build_info().fps);
  std::vector<std::unique_ptr<recon::FrameBones>> bones;
  for (const auto& c : configs) bones.push_back(std::make_unique<recon::FrameBones>(*c.db));

  std::size_t frames = 0;
  for (const auto& t : truth) frames += t.world.size();
  std::cerr << "evaluating " << configs.size() << " configurations on " << truth.size()
            << " held-out clips (" << frames << " frames) x " << cameras.size() << " cameras x "
            << conditions.size() << " conditions\n";
  ProgressBar bar;
  const auto summed = run_jobs(configs, cameras, conditions, truth, bones,
                               static_cast<int>(std::clamp(args.integer("threads"), 1L, 64L)), bar);
  bar.finish();
  auto at = [&](std::size_t c, std::size_t k, std::size_t n) -> const eval::Scores& {
    return summed[(c * cameras.size() + k) * conditions.size() + n];
  };

  json out = {{"protocol", "virtual"},
              {"command", "mocap eval virtual"},
              {"git_commit", git_commit()},
              {"machine", machine_description()},
              {"database", json::parse(full.options_json())},
              {"paper_database", json::parse(paper.options_json())},
              {"clips", truth.size()},
              {"frames", frames}};
  std::cout << "## Virtual protocol: " << truth.size() << " held-out clips, " << frames
            << " frames at " << full.build_info().fps << " fps, " << cameras.size()
            << " cameras\n\n"
            << "| configuration | condition | MPJPE mm | PA-MPJPE mm | accel err mm/f² | jitter "
               "mm/f² | coverage |\n"
            << "|---|---|---:|---:|---:|---:|---:|\n";
  for (std::size_t c = 0; c < configs.size(); ++c) {
    json per_condition = json::object(), per_family = json::object();
    for (std::size_t n = 0; n < conditions.size(); ++n) {
      eval::Scores s;
      for (std::size_t k = 0; k < cameras.size(); ++k) s.add(at(c, k, n));
      print_row(configs[c].name, conditions[n].label(), s);
      per_condition[conditions[n].label()] = scores_json(s);
    }
    std::map<std::string, eval::Scores> families;
    for (std::size_t k = 0; k < cameras.size(); ++k)
      for (std::size_t n = 0; n < conditions.size(); ++n)
        families[cameras[k].family].add(at(c, k, n));
    for (const auto& [family, s] : families) per_family[family] = scores_json(s);
    out["configurations"][configs[c].name] = {{"description", configs[c].description},
                                              {"per_condition", per_condition},
                                              {"per_camera_family", per_family}};
  }
  std::cout << "\n| configuration | camera family (all conditions) | MPJPE mm | PA-MPJPE mm | "
               "accel err mm/f² | jitter mm/f² | coverage |\n"
            << "|---|---|---:|---:|---:|---:|---:|\n";
  for (std::size_t c = 0; c < configs.size(); ++c) {
    for (const auto& [family, s] :
         out["configurations"][configs[c].name]["per_camera_family"].items()) {
      (void)s;
      eval::Scores sum;
      for (std::size_t k = 0; k < cameras.size(); ++k)
        if (cameras[k].family == family)
          for (std::size_t n = 0; n < conditions.size(); ++n) sum.add(at(c, k, n));
      print_row(configs[c].name, family, sum);
    }
  }
  std::cout << "\nConfigurations:\n";
  for (const auto& c : configs) std::cout << "- " << c.name << ": " << c.description << "\n";
  out["seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::ofstream(args.get("json")) << out.dump(2) << "\n";
  std::cout << "\nAll numbers: " << args.get("json") << "\n";
  return 0;
}

}  // namespace

int eval_command(int argc, char** argv) {
  const std::string usage =
      "usage: mocap eval virtual|humaneva ...\n\n"
      "  virtual    the paper's virtual-video protocol on held-out CMU subjects\n\n"
      "Run 'mocap eval SUBCOMMAND --help' for options.\n";
  if (argc < 1) {
    std::cerr << usage;
    return 2;
  }
  const std::string sub = argv[0];
  if (sub == "virtual") return virtual_protocol(argc - 1, argv + 1);
  if (sub == "--help" || sub == "-h") {
    std::cout << usage;
    return 0;
  }
  std::cerr << "mocap eval: unknown subcommand '" << sub << "'\n\n" << usage;
  return 2;
}

}  // namespace mocap::cli
