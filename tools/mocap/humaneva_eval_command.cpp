// `mocap eval humaneva`: the HumanEva-I protocol of ../shared/docs/EVALUATION.md. The
// configurations of `mocap eval virtual`, run once with the CMU train database (different people
// and markers: the cross-dataset case) and once with databases built from HumanEva's own Train
// split (the published methods' setting), on the Validate split's ground-truth 2D with the
// virtual protocol's noise levels.

#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "eval/humaneva_protocol.hpp"
#include "eval_configs.hpp"
#include "eval_leaks.hpp"
#include "eval_report.hpp"
#include "motion/canonical_body.hpp"
#include "output_files.hpp"
#include "posedb/parallel_chunks.hpp"
#include "progress_bar.hpp"
#include "recon/layout_offsets.hpp"

namespace mocap::cli {
namespace {

using nlohmann::json;
namespace he = io::humaneva;

// The actions the HumanEva databases are built from: the evaluated ones, as VideoPose3D trains
// (`-a Walk,Jog,Box`).
std::vector<std::string_view> training_actions() {
  std::vector<std::string_view> actions;
  for (const auto& a : eval::kHumanEvaActions) actions.push_back(a.data_name);
  return actions;
}

// The databases one row group of the tables uses: the full view set and the paper's.
struct DatabaseFamily {
  std::string name;
  std::string description;
  posedb::Database full;
  std::optional<posedb::Database> paper;  // absent when no selected configuration needs it
};

// Build options that give the view set, scaling and rate of an existing database.
posedb::BuildOptions same_views_as(const posedb::BuildInfo& info, const std::string& command,
                                   int threads) {
  posedb::BuildOptions options;
  options.fps = info.fps;
  options.views = info.views;
  options.scaling = info.scaling;
  options.seed = info.seed;
  options.threads = threads;
  options.command = command;
  return options;
}

posedb::Database build_from_humaneva(const std::vector<posedb::BodySequence>& motion,
                                     const posedb::BuildOptions& options, const std::string& tag) {
  posedb::BuildReport report;
  const auto contents = posedb::build_database_from_bodies(motion, options, {}, report);
  for (const auto& skipped : report.skipped) std::cerr << "skipped " << skipped << "\n";
  return open_temporary_database(contents, tag);
}

constexpr const char* kTrainedOn = "HumanEva-I Train S1-S3, Walk/Jog/Box";

// The HumanEva database with all views: the file given, or one built with the CMU database's
// view set so that only the motion differs between the two rows of the tables.
posedb::Database humaneva_full_database(const std::vector<posedb::BodySequence>& motion,
                                        const posedb::Database& cmu, const std::string& given,
                                        int threads) {
  const double fps = cmu.build_info().fps;
  if (given.empty()) {
    const std::string command =
        std::string("mocap eval humaneva (") + kTrainedOn + ", view set of " + cmu.path() + ")";
    return build_from_humaneva(motion, same_views_as(cmu.build_info(), command, threads),
                               "humaneva");
  }
  posedb::Database db = posedb::Database::open(given);
  if (db.build_info().fps != fps)
    throw InputError(given, "built at " + std::to_string(db.build_info().fps) +
                                " fps, the CMU database at " + std::to_string(fps) +
                                ": both must have the same rate");
  return db;
}

// HumanEva's own databases: the full view set and the paper's.
DatabaseFamily humaneva_family(const he::Dataset& data, const posedb::Database& cmu,
                               const std::string& given, int threads, bool with_paper) {
  const auto motion = eval::humaneva_body_sequences(data, he::Split::train, training_actions());
  std::cerr << "building the HumanEva Train databases from " << motion.size() << " chunks\n";
  posedb::BuildOptions paper_options =
      paper_build_options(std::string("mocap eval humaneva (") + kTrainedOn +
                          ", paper database: yaw-only views at 1.5 m)");
  paper_options.fps = cmu.build_info().fps;
  paper_options.threads = threads;
  DatabaseFamily family{"HumanEva Train", std::string("built from ") + kTrainedOn,
                        humaneva_full_database(motion, cmu, given, threads), std::nullopt};
  if (with_paper) family.paper = build_from_humaneva(motion, paper_options, "humaneva-paper");
  return family;
}

struct Job {
  std::size_t family, config, condition, sequence;
};

// Each subject's proportions measured on the Train split (Walk, Jog, Box), its joints first
// moved onto the canonical joints with the HumanEva-15 offsets (3D, forward included): the
// shoulders and hips are joint centres in both, the neck, head and root are not.
std::map<std::string, motion::BodyProportions> train_proportions(
    const he::Dataset& data, const recon::LayoutOffsets& offsets) {
  std::map<std::string, motion::BodyProportions> out;
  for (const std::string_view subject : eval::kHumanEvaSubjects) {
    std::vector<motion::Body15> frames;
    for (const auto& action : eval::kHumanEvaActions)
      for (const he::Chunk* chunk : data.select(he::Split::train, subject, action.data_name))
        for (const he::Pose3& pose : chunk->positions_3d) {
          motion::Body15 body = he::to_body15(pose);
          recon::apply_layout_offsets_3d(offsets, body, 1.0f);
          frames.push_back(body);
        }
    if (frames.empty())
      throw InputError(std::string(he::kPositions3dFile),
                       "no Train frames of " + std::string(subject) + " to measure");
    out[std::string(subject)] = motion::measure_proportions(frames, true);
  }
  return out;
}

// Where a variant applies the layout offsets: not at all, to the 2D input before matching
// (SequenceOptions::layout_offsets) or to the matcher's candidates (Matcher::set_layout).
enum class OffsetsOn { none, input, candidates };

// A configuration as one run compares it: with or without the layout offsets of the input
// (HumanEva-15 -> canonical joints), on the database's body or the person's Train proportions.
struct Variant {
  Config config;
  const recon::LayoutOffsets* offsets = nullptr;
  OffsetsOn on = OffsetsOn::none;
  const std::map<std::string, motion::BodyProportions>* person = nullptr;  // per subject
};

// One row of the tables: a name and its scores per (condition, sequence), in job order.
struct Row {
  std::string name, description;
  std::vector<eval::Scores> scores;
};

// Every (family, variant, condition) for every sequence, on `threads` threads. A matcher per
// job: it is cheap to make and keeps scratch space, so it is never shared between threads. A
// variant with offsets gives two rows: its canonical output, and that output mapped back into
// HumanEva-15's own joint definition.
std::vector<std::vector<Row>> run_jobs(const std::vector<std::vector<Variant>>& variants,
                                       const std::vector<eval::Condition>& conditions,
                                       const std::vector<eval::HumanEvaSequence>& sequences,
                                       int threads) {
  std::vector<Job> jobs;
  for (std::size_t f = 0; f < variants.size(); ++f)
    for (std::size_t c = 0; c < variants[f].size(); ++c)
      for (std::size_t n = 0; n < conditions.size(); ++n)
        for (std::size_t s = 0; s < sequences.size(); ++s) jobs.push_back({f, c, n, s});
  std::map<const posedb::Database*, std::unique_ptr<recon::FrameBones>> bones;
  for (const auto& family : variants)
    for (const Variant& v : family)
      if (!bones.contains(v.config.db))
        bones[v.config.db] = std::make_unique<recon::FrameBones>(*v.config.db);
  std::vector<eval::Scores> results(jobs.size()), mapped(jobs.size());
  ProgressBar bar;
  posedb::for_each_chunk(
      jobs.size(), threads,
      [&](std::size_t i) {
        const Job& job = jobs[i];
        const Variant& variant = variants[job.family][job.config];
        const Config& config = variant.config;
        recon::Matcher matcher(*config.db, config.match);
        if (variant.person) matcher.set_person(variant.person->at(sequences[job.sequence].subject));
        const std::uint64_t seed = 1000003ull * job.sequence + job.condition;  // same for all
        recon::SequenceOptions options = config.sequence;
        if (config.align_to_ray) options.camera = sequences[job.sequence].camera;
        if (variant.on == OffsetsOn::input) options.layout_offsets = *variant.offsets;
        if (variant.on == OffsetsOn::candidates) matcher.set_layout(*variant.offsets);
        results[i] = eval::evaluate_sequence(matcher, *bones.at(config.db), sequences[job.sequence],
                                             conditions[job.condition], options, seed,
                                             variant.offsets, &mapped[i]);
      },
      [&](std::size_t done) {
        bar.update("evaluate", static_cast<double>(done) / static_cast<double>(jobs.size()));
      });
  bar.finish();
  std::vector<std::vector<Row>> rows(variants.size());
  std::size_t i = 0;
  for (std::size_t f = 0; f < variants.size(); ++f) {
    for (const Variant& v : variants[f]) {
      const std::size_t n = conditions.size() * sequences.size();
      Row row{v.config.name, v.config.description, {}};
      if (v.person) {
        row.name += " + Train proportions";
        row.description +=
            "; candidates re-scored on the subject's proportions measured on HumanEva Train";
      }
      row.scores.assign(results.begin() + i, results.begin() + i + n);
      if (v.offsets) {
        const std::string name = row.name, description = row.description;
        const std::string how =
            v.on == OffsetsOn::input
                ? "input moved onto the canonical joints (" + v.offsets->source + ")"
                : "candidates moved into HumanEva-15 (" + v.offsets->source +
                      ", 3D, forward included) and re-scored";
        row.name += v.on == OffsetsOn::input ? " + 2D offsets" : " + candidate offsets";
        row.description += "; " + how + ", output canonical";
        Row back{row.name + ", mapped back",
                 description + "; " + how +
                     ", output mapped back into HumanEva-15's thorax/pelvis/headDistal",
                 {}};
        back.scores.assign(mapped.begin() + i, mapped.begin() + i + n);
        rows[f].push_back(std::move(row));
        rows[f].push_back(std::move(back));
      } else {
        rows[f].push_back(std::move(row));
      }
      i += n;
    }
  }
  return rows;
}

std::string cell_name(std::string_view action, std::string_view subject) {
  return std::string(action) + " " + std::string(subject);
}

void print_cells_header(const std::string& split, const std::string& family) {
  std::cout << "\n## HumanEva-I " << split << ", " << family
            << " database: PA-MPJPE mm per action and subject\n\n| configuration | condition |";
  for (const auto& a : eval::kHumanEvaActions)
    for (const auto s : eval::kHumanEvaSubjects) std::cout << " " << cell_name(a.label, s) << " |";
  std::cout << " mean |\n|---|---|";
  for (std::size_t i = 0; i <= eval::kHumanEvaActions.size() * eval::kHumanEvaSubjects.size(); ++i)
    std::cout << "---:|";
  std::cout << "\n";
}

void print_cells_row(const std::string& config, const std::string& condition,
                     const eval::HumanEvaTable& table) {
  std::cout << "| " << config << " | " << condition << " |" << std::fixed << std::setprecision(1);
  for (const auto& a : eval::kHumanEvaActions)
    for (const auto s : eval::kHumanEvaSubjects)
      std::cout << " " << table.cell(s, a.label).pa_mpjpe() << " |";
  std::cout << " " << table.mean_cell_pa_mpjpe() << " |\n";
}

json table_json(const eval::HumanEvaTable& table) {
  json cells = json::object();
  for (const auto& a : eval::kHumanEvaActions)
    for (const auto s : eval::kHumanEvaSubjects)
      cells[cell_name(a.label, s)] = scores_json(table.cell(s, a.label));
  return {{"cells", cells},
          {"mean_of_cells_pa_mpjpe_mm", table.mean_cell_pa_mpjpe()},
          {"all_frames", scores_json(table.all())}};
}

constexpr const char* kRateNote =
    "HumanEva is 60 Hz, the databases 24 fps: the 2D input and the 3D truth are both resampled to "
    "the database rate by linear interpolation, noise is added per evaluated frame, and the "
    "acceleration error is in mm/frame^2 at that rate";
constexpr const char* kJointNote =
    "every Body15 joint is one HumanEva-15 joint, none derived or dropped; MPJPE and PA-MPJPE "
    "average the 14 non-root joints (root = HumanEva pelvis, torsoDistal, not the mid-hip point; "
    "head = headDistal)";

// Tables per family and the JSON of every number.
json report(const std::vector<DatabaseFamily>& families, const std::vector<std::vector<Row>>& rows,
            const std::vector<eval::Condition>& conditions,
            const std::vector<eval::HumanEvaSequence>& sequences, const std::string& split) {
  json out = json::object();
  for (std::size_t f = 0; f < families.size(); ++f) {
    print_cells_header(split, families[f].name);
    struct Total {
      std::string config, condition;
      eval::Scores scores;
    };
    std::vector<Total> totals;
    json per_config = json::object();
    for (const Row& row : rows[f]) {
      std::size_t i = 0;  // scores are in job order: condition, sequence
      json per_condition = json::object();
      for (const eval::Condition& condition : conditions) {
        eval::HumanEvaTable table;
        for (const auto& sequence : sequences) table.add(sequence, row.scores[i++]);
        print_cells_row(row.name, condition.label(), table);
        per_condition[condition.label()] = table_json(table);
        totals.push_back({row.name, condition.label(), table.all()});
      }
      per_config[row.name] = {{"description", row.description}, {"per_condition", per_condition}};
    }
    std::cout
        << "\n## HumanEva-I " << split << ", " << families[f].name
        << " database: all frames\n\n| configuration | condition | MPJPE mm | PA-MPJPE mm "
           "| accel err mm/f² | jitter mm/f² | coverage |\n|---|---|---:|---:|---:|---:|---:|\n";
    for (const Total& t : totals) print_row(t.config, t.condition, t.scores);
    json entry = {{"description", families[f].description},
                  {"database_frames", families[f].full.frames().size()},
                  {"database_projections", families[f].full.projections().rows},
                  {"database", json::parse(families[f].full.options_json())},
                  {"configurations", per_config}};
    if (families[f].paper) entry["paper_database"] = json::parse(families[f].paper->options_json());
    out[families[f].name] = entry;
  }
  return out;
}

json sequences_json(const std::vector<eval::HumanEvaSequence>& sequences) {
  std::size_t frames = 0;
  for (const auto& s : sequences) frames += s.input.size();
  return {{"sequences", sequences.size()}, {"frames", frames}};
}

}  // namespace

int humaneva_eval_command(int argc, char** argv) {
  Args args("mocap eval humaneva --db CMU_TRAIN_DB [options]",
            "HumanEva-I (Validate S1-S3; Walk, Jog, Box; cameras C1-C3) from ground-truth 2D with "
            "the virtual\nprotocol's noise levels: PA-MPJPE per subject and action, MPJPE, "
            "acceleration error, once with the\nCMU train database and once with databases built "
            "from HumanEva's Train split. Prints Markdown\ntables and writes every number as "
            "JSON.");
  args.option("db", "FILE",
              "database built from the CMU train split (mocap db build ... --split "
              "train)")
      .option("paper-db", "FILE",
              "the paper's yaw-only 1.5 m CMU database (built from --mocap when absent)")
      .option("mocap", "DIR", "cmu31 folder with splits.txt", "../shared/data/mocap/cmu31")
      .option("humaneva-db", "FILE",
              "database built from HumanEva Train (built with the --db view set when absent)")
      .option("data", "DIR", "HumanEva-I in the VideoPose3D format",
              "../shared/data/eval/humaneva_i_videopose3d")
      .option("json", "FILE", "where to write all numbers", "eval_humaneva.json")
      .option("threads", "N", "worker threads", "2", Range::count(1, 64))
      .option("configs", "NAMES",
              "comma-separated configurations to run (e.g. 'per-frame NN,full: path + SG + ray + "
              "view'; all when absent)")
      .option("layout-offsets", "off|auto|FILE|compare|compare:FILE",
              "correct for the HumanEva-15 keypoints not being the canonical joints when "
              "matching with the CMU database (auto: calibration/layouts/humaneva15.yaml): "
              "the matcher's candidates are moved into HumanEva-15 and re-scored (\"+ candidate "
              "offsets\"); compare: every configuration without, with the 2D input moved onto "
              "the canonical joints (\"+ 2D offsets\") and with candidate offsets. Rows with "
              "offsets are scored twice: the canonical output, and that output mapped back into "
              "HumanEva's own joints",
              "off")
      .flag("train-proportions",
            "run every CMU-database row once more with the candidates re-scored on each "
            "subject's\nproportions measured on HumanEva Train (\"+ Train proportions\")")
      .option("evaluate-on", "validate|train",
              "the split evaluated: train only to choose settings (the HumanEva databases are "
              "built from it)",
              "validate")
      .flag("no-humaneva-db", "skip the databases built from HumanEva Train")
      .flag("quick", "2 noise levels instead of 5")
      .flag("allow-leak",
            "evaluate even when a database holds clips of the evaluated HumanEva split "
            "(refused otherwise); the results then say so, loudly");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("db")) throw InputError("--db", "required: a database built from the train split");
  refuse_output_over_inputs({"--json", args.get("json")},
                            {{"--db", args.get("db")},
                             {"--paper-db", args.get("paper-db")},
                             {"--humaneva-db", args.get("humaneva-db")}});
  const auto started = std::chrono::steady_clock::now();
  const int threads = static_cast<int>(args.integer("threads"));
  // The databases are checked for the evaluated motion before anything is loaded.
  const bool on_train = args.get("evaluate-on") == "train";
  if (!on_train && args.get("evaluate-on") != "validate")
    throw InputError("--evaluate-on", "validate or train");
  if (on_train && !args.has("no-humaneva-db"))
    throw InputError("--evaluate-on", "train needs --no-humaneva-db (those databases are Train)");
  const std::string evaluated_split = on_train ? "Train" : "Validate";
  LeakCheck leaks;
  for (const std::string option : {"db", "paper-db", "humaneva-db"}) {
    if (args.has(option) && (option != "humaneva-db" || !args.has("no-humaneva-db")))
      leaks.add(args.get(option),
                humaneva_clips(posedb::Database::open(args.get(option)), evaluated_split));
  }
  leaks.enforce(args.has("allow-leak"), "HumanEva-I " + evaluated_split, "mocap eval humaneva");
  const std::string folder = args.get("data");
  const he::Dataset data = he::load_dataset(folder);
  const auto cameras = he::load_cameras(std::filesystem::path(folder) / he::kCamerasFile);

  std::vector<std::string> wanted;
  if (args.has("configs")) {
    std::stringstream list(args.get("configs"));
    for (std::string name; std::getline(list, name, ',');)
      if (!name.empty()) wanted.push_back(name);
  }
  const auto selected = [&](const std::string& name) {
    return wanted.empty() || std::find(wanted.begin(), wanted.end(), name) != wanted.end();
  };
  const bool with_paper = selected("paper");

  const std::string offsets_setting = args.get("layout-offsets");
  const bool compare = offsets_setting.starts_with("compare");
  const std::string offsets_file = offsets_setting.starts_with("compare:")
                                       ? offsets_setting.substr(8)
                                   : compare ? "auto"
                                             : offsets_setting;
  const std::optional<recon::LayoutOffsets> offsets =
      offsets_setting == "off" ? std::nullopt
                               : recon::resolve_layout_offsets(offsets_file, LayoutId::humaneva15);
  if (offsets_setting != "off" && !offsets)
    throw InputError("--layout-offsets", "no " +
                                             recon::layout_offsets_file_name(LayoutId::humaneva15) +
                                             " in calibration/layouts (mocap calibrate layout)");

  std::optional<std::map<std::string, motion::BodyProportions>> proportions;
  if (args.has("train-proportions")) {
    const auto definition =
        offsets ? offsets : recon::resolve_layout_offsets("auto", LayoutId::humaneva15);
    if (!definition)
      throw InputError("--train-proportions",
                       "needs calibration/layouts/humaneva15.yaml (the canonical neck, head and "
                       "root in HumanEva's joints)");
    proportions = train_proportions(data, *definition);
    for (const auto& [subject, p] : *proportions)
      std::cerr << subject << " Train proportions: " << motion::describe(p) << "\n";
  }

  std::vector<DatabaseFamily> families;
  posedb::Database cmu = posedb::Database::open(args.get("db"));
  std::optional<posedb::Database> cmu_paper;
  if (with_paper)
    cmu_paper = open_paper_database(args.get("paper-db"), args.get("mocap"), "mocap eval humaneva");
  std::optional<DatabaseFamily> own;
  if (!args.has("no-humaneva-db"))
    own = humaneva_family(data, cmu, args.get("humaneva-db"), threads, with_paper);
  families.push_back(
      {"CMU train", "the --db database (cross-dataset)", std::move(cmu), std::move(cmu_paper)});
  if (own) families.push_back(std::move(*own));
  const double fps = families.front().full.build_info().fps;

  // Offsets apply to the CMU database only: the HumanEva databases are made of HumanEva's own
  // joints (thorax, pelvis, headDistal), which its 2D input already matches.
  std::vector<std::vector<Variant>> variants;
  for (std::size_t f = 0; f < families.size(); ++f) {
    const auto& family = families[f];
    std::vector<Variant> list;
    for (const Config& c :
         make_configs(family.full, family.paper ? *family.paper : family.full, fps)) {
      if (!selected(c.name)) continue;
      const bool cmu_family = f == 0;
      std::vector<const std::map<std::string, motion::BodyProportions>*> people = {nullptr};
      if (proportions && cmu_family) people.push_back(&*proportions);
      for (const auto* person : people) {
        if (!offsets || compare || !cmu_family)
          list.push_back({c, nullptr, OffsetsOn::none, person});
        if (offsets && cmu_family && compare)
          list.push_back({c, &*offsets, OffsetsOn::input, person});
        if (offsets && cmu_family) list.push_back({c, &*offsets, OffsetsOn::candidates, person});
      }
    }
    if (list.empty()) throw InputError("--configs", "no configuration of that name");
    variants.push_back(std::move(list));
  }
  const auto conditions = eval::default_conditions(args.has("quick"));
  const auto sequences = eval::humaneva_validation_sequences(
      data, cameras, fps, on_train ? he::Split::train : he::Split::validate);
  std::cerr << "evaluating " << variants.front().size() << " configurations x " << families.size()
            << " databases on " << sequences.size() << " sequences (chunk x camera) x "
            << conditions.size() << " conditions\n";
  const auto rows = run_jobs(variants, conditions, sequences, threads);

  json out = {{"protocol", "humaneva"},
              {"command", command_line("mocap eval humaneva", argc, argv)},
              {"git_commit", git_commit()},
              {"machine", machine_description()},
              {"data", folder},
              {"evaluation_fps", fps},
              {"rate", kRateNote},
              {"joints", kJointNote},
              {"joint_correspondence", eval::humaneva_joint_correspondence()},
              {"validation", sequences_json(sequences)}};
  out["evaluated_split"] = evaluated_split;
  out["leak"] = leaks.to_json();
  std::cout << leaks.markdown_warning();
  if (offsets) out["layout_offsets"] = offsets->source;
  if (proportions)
    for (const auto& [subject, p] : *proportions)
      out["train_proportions"][subject] = motion::describe(p);
  out["results"] = report(families, rows, conditions, sequences, on_train ? "Train" : "Validate");
  std::cout << "\nJoints: " << kJointNote << ":\n";
  for (const auto& line : eval::humaneva_joint_correspondence()) std::cout << "- " << line << "\n";
  std::cout << "\nRate: " << kRateNote << ".\n\nConfigurations:\n";
  for (const auto& row : rows.front())
    std::cout << "- " << row.name << ": " << row.description << "\n";
  write_results(out, args.get("json"), started);
  return 0;
}

}  // namespace mocap::cli
