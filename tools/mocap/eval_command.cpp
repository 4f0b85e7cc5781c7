// `mocap eval virtual | humaneva | ... | multiview | pose2sim`: the evaluation protocols of
// ../shared/docs/EVALUATION.md.

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
#include "eval_configs.hpp"
#include "eval_leaks.hpp"
#include "eval_report.hpp"
#include "motion/canonical_body.hpp"
#include "output_files.hpp"
#include "posedb/builder.hpp"
#include "posedb/database.hpp"
#include "progress_bar.hpp"

namespace mocap::cli {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

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
                                   const recon::LayoutOffsets* input_layout, int threads,
                                   ProgressBar& bar) {
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
      matchers[j.config]->set_person(
          configs[j.config].person_bones
              ? std::optional(motion::measure_proportions(truth[j.sequence].world, false))
              : std::nullopt);
      matchers[j.config]->set_layout(configs[j.config].candidate_layout);
      const std::uint64_t seed = 1000003ull * j.sequence + 1009ull * j.camera +
                                 j.condition;  // same input for every config
      const auto rendered = eval::render(truth[j.sequence], cameras[j.camera], {},
                                         conditions[j.condition], seed, input_layout);
      recon::SequenceOptions options = configs[j.config].sequence;
      if (configs[j.config].align_to_ray) {
        const eval::Image image;
        options.camera =
            camera::Camera::from_fov(image.width, image.height, image.horizontal_fov_deg);
      }
      const auto poses = recon::reconstruct_sequence(*matchers[j.config], *bones[j.config],
                                                     rendered.input, options);
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

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

// With an input layout: the configuration as it is, then with the layout's offsets applied to
// the 2D input, then with them applied to the matcher's candidates (Matcher::set_layout).
std::vector<Config> layout_variants(const Config& c,
                                    const std::optional<recon::LayoutOffsets>& layout) {
  if (!layout) return {c};
  Config input = c, candidates = c;
  input.name += " + 2D offsets";
  input.description += "; the layout's offsets applied to the 2D input (" + layout->source + ")";
  input.sequence.layout_offsets = layout;
  candidates.name += " + candidate offsets";
  candidates.description += "; candidates moved into the layout (" + layout->source +
                            ", 3D, forward included) and re-scored";
  candidates.candidate_layout = layout;
  return {c, input, candidates};
}

// The configurations of every database (named "[label] ..." when there are several), the
// paper's once, filtered by --configs, each doubled with --person-bones (and tripled with an
// input layout, layout_variants).
std::vector<Config> select_configs(const std::vector<posedb::Database>& databases,
                                   const std::vector<std::string>& labels,
                                   const posedb::Database& paper, const Args& args,
                                   const std::optional<recon::LayoutOffsets>& layout) {
  const auto prefixes = split_list(args.has("configs") ? args.get("configs") : "");
  auto wanted = [&](const std::string& name) {
    return prefixes.empty() || std::any_of(prefixes.begin(), prefixes.end(), [&](const auto& p) {
             return name.compare(0, p.size(), p) == 0;
           });
  };
  std::vector<Config> out;
  for (std::size_t d = 0; d < databases.size(); ++d) {
    for (Config c : make_configs(databases[d], paper, databases[d].build_info().fps)) {
      const bool is_paper = c.db == &paper;
      if (!wanted(c.name) || (is_paper && d > 0)) continue;
      if (databases.size() > 1 && !is_paper) c.name = "[" + labels[d] + "] " + c.name;
      for (Config v : layout_variants(c, layout)) {
        out.push_back(v);
        if (args.has("person-bones") && !is_paper) {
          v.name += " + person bones";
          v.description += "; candidates re-scored on the person's proportions (given)";
          v.person_bones = true;
          out.push_back(v);
        }
      }
    }
  }
  if (out.empty()) throw InputError("--configs", "no configuration matches");
  return out;
}

json databases_json(const std::vector<posedb::Database>& databases,
                    const std::vector<std::string>& labels) {
  json out = json::array();
  for (std::size_t d = 0; d < databases.size(); ++d) {
    std::map<std::string, std::uint64_t> frames;
    for (const auto& c : databases[d].clips()) frames[c.family] += c.frame_count;
    out.push_back({{"label", labels[d]},
                   {"file", databases[d].path()},
                   {"frames", databases[d].frames().size()},
                   {"frames_per_family", frames},
                   {"build", json::parse(databases[d].options_json())}});
  }
  return out;
}

int virtual_protocol(int argc, char** argv) {
  Args args(
      "mocap eval virtual --db DB [options]",
      "The paper's virtual-video protocol on the held-out CMU subjects: cameras at several yaws, "
      "heights and\n"
      "pitches, 2D noise and joint drop-out; MPJPE, PA-MPJPE, acceleration error and jitter per "
      "configuration,\n"
      "noise level and camera family. Prints Markdown tables and writes every number as JSON.");
  args.option("db", "[LABEL=]FILE",
              "database built from the train split (mocap db build ... --split train); repeat "
              "to compare\nseveral side by side in one run (configurations named [LABEL] ..., "
              "LABEL = file stem\nwhen not given)",
              std::nullopt, true)
      .option("configs", "LIST",
              "only the configurations whose names start with one of these comma-separated "
              "prefixes\n(e.g. \"per-frame NN,full:\"); all when absent")
      .flag("person-bones",
            "add each configuration once more with the candidates re-scored on the person's "
            "own\nproportions, given from the truth clip (\"... + person bones\")")
      .option("paper-db", "FILE",
              "the paper's yaw-only 1.5 m database (built from the train split when absent)")
      .option("mocap", "DIR", "cmu31 folder with splits.txt", "../shared/data/mocap/cmu31")
      .option("json", "FILE", "where to write all numbers", "eval_virtual.json")
      .option("threads", "N", "worker threads", "2", Range::count(1, 64))
      .option("clips", "N", "use only the first N held-out clips (0 = all)", "0",
              Range::count(0, 1'000'000))
      .option("input-layout", "FILE",
              "render the 2D input in this layout's keypoint definition (calibration/layouts/"
              "*.yaml;\nthe truth stays canonical) and run every configuration as is, \"+ 2D "
              "offsets\" and\n\"+ candidate offsets\" (docs/keypoint-layouts.md)")
      .flag("quick", "2 yaws per camera family and 2 noise levels")
      .flag("allow-leak",
            "evaluate even when a database holds held-out CMU subjects' clips (refused "
            "otherwise); the results then say so, loudly");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("db")) throw InputError("--db", "required: a database built from the train split");
  std::vector<NamedPath> inputs;
  for (const std::string& given : args.all("db"))
    inputs.push_back(
        {"--db", given.substr(given.find('=') == std::string::npos ? 0 : given.find('=') + 1)});
  inputs.push_back({"--paper-db", args.get("paper-db")});
  inputs.push_back({"--input-layout", args.get("input-layout")});
  refuse_output_over_inputs({"--json", args.get("json")}, inputs);
  const auto started = std::chrono::steady_clock::now();
  std::vector<std::string> labels;
  std::vector<posedb::Database> databases;
  for (const std::string& given : args.all("db")) {
    const auto eq = given.find('=');
    const std::string file = eq == std::string::npos ? given : given.substr(eq + 1);
    labels.push_back(eq == std::string::npos ? fs::path(file).stem().string()
                                             : given.substr(0, eq));
    databases.push_back(posedb::Database::open(file));
    if (databases.back().build_info().fps != databases.front().build_info().fps)
      throw InputError(file, "built at another frame rate than the first --db");
  }
  const posedb::Database& full = databases.front();
  const std::string mocap = args.get("mocap");
  LeakCheck leaks;
  for (const posedb::Database& db : databases) leaks.add(db.path(), cmu_heldout_clips(db, mocap));
  if (args.has("paper-db")) {
    leaks.add(args.get("paper-db"),
              cmu_heldout_clips(posedb::Database::open(args.get("paper-db")), mocap));
  }
  leaks.enforce(args.has("allow-leak"), "the held-out CMU subjects", "mocap eval virtual");
  const posedb::Database paper =
      open_paper_database(args.get("paper-db"), mocap, "mocap eval virtual");

  auto truth = eval::load_truth(posedb::split_files(mocap, "heldout"), full.build_info().fps);
  if (const long n = args.integer("clips"); n > 0 && static_cast<std::size_t>(n) < truth.size())
    truth.resize(n);
  const auto cameras = eval::default_cameras(args.has("quick"));
  const auto conditions = eval::default_conditions(args.has("quick"));
  std::optional<recon::LayoutOffsets> input_layout;
  if (args.has("input-layout")) input_layout = recon::load_layout_offsets(args.get("input-layout"));
  const auto configs = select_configs(databases, labels, paper, args, input_layout);
  std::vector<std::unique_ptr<recon::FrameBones>> bones;
  for (const auto& c : configs) bones.push_back(std::make_unique<recon::FrameBones>(*c.db));

  std::size_t frames = 0;
  for (const auto& t : truth) frames += t.world.size();
  std::cerr << "evaluating " << configs.size() << " configurations on " << truth.size()
            << " held-out clips (" << frames << " frames) x " << cameras.size() << " cameras x "
            << conditions.size() << " conditions\n";
  ProgressBar bar;
  const auto summed =
      run_jobs(configs, cameras, conditions, truth, bones, input_layout ? &*input_layout : nullptr,
               static_cast<int>(args.integer("threads")), bar);
  bar.finish();
  auto at = [&](std::size_t c, std::size_t k, std::size_t n) -> const eval::Scores& {
    return summed[(c * cameras.size() + k) * conditions.size() + n];
  };

  json out = {{"protocol", "virtual"},
              {"command", "mocap eval virtual"},
              {"git_commit", git_commit()},
              {"machine", machine_description()},
              {"database", json::parse(full.options_json())},
              {"databases", databases_json(databases, labels)},
              {"paper_database", json::parse(paper.options_json())},
              {"input_layout", input_layout ? input_layout->source : "canonical joints"},
              {"clips", truth.size()},
              {"frames", frames},
              {"leak", leaks.to_json()}};
  std::cout << leaks.markdown_warning() << "## Virtual protocol: " << truth.size()
            << " held-out clips, " << frames << " frames at " << full.build_info().fps << " fps, "
            << cameras.size() << " cameras\n\n"
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
  std::cout << "\nDatabases:\n";
  for (const auto& d : out["databases"]) {
    std::cout << "- " << d["label"].get<std::string>() << ": " << d["file"].get<std::string>()
              << ", body " << d["build"].value("body", "source") << ", " << d["frames"]
              << " frames (";
    const char* sep = "";
    for (const auto& [family, n] : d["frames_per_family"].items())
      std::cout << sep << family << " " << n, sep = ", ";
    std::cout << ")\n";
  }
  write_results(out, args.get("json"), started);
  return 0;
}

}  // namespace

int eval_command(int argc, char** argv) {
  static constexpr Subcommand kSubcommands[] = {
      {"virtual", "the paper's virtual-video protocol on held-out CMU subjects", virtual_protocol},
      {"humaneva", "HumanEva-I Validate from ground-truth 2D, CMU and HumanEva databases",
       humaneva_eval_command},
      {"humaneva-fit", "HumanEva-I Validate with its cameras, before and after skeleton fitting",
       humaneva_fit_command},
      {"humaneva-multiview",
       "HumanEva-I Validate with 2 and 3 of its cameras at once, next to each camera alone",
       humaneva_multiview_command},
      {"crossview", "cross-view consistency (paper 5.3): Pose2Sim 4 views, HumanEva-I 3 views",
       crossview_eval_command},
      {"multiview", "multi-view virtual protocol on held-out CMU clips: baseline, ours, + tracking",
       multiview_eval_command},
      {"pose2sim", "Pose2Sim's demo: our multi-view 3D against its triangulated TRC",
       pose2sim_eval_command},
  };
  return run_subcommand("eval", kSubcommands, argc, argv);
}

}  // namespace mocap::cli
