// `mocap eval humaneva-multiview`: HumanEva-I Validate with two and three of its calibrated
// cameras at once (components/multiview + the multi-view fit), and the same chunks and frames
// through each camera alone (the monocular protocol's retrieval, then the monocular fit), in one
// table per noise level (issue 19, report 3). The work is in components/eval
// (humaneva_multiview.hpp, humaneva_protocol.hpp) and components/fit (view_fit.hpp); this file
// runs the jobs, masks the frames every row reconstructed, and prints.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "eval/humaneva_multiview.hpp"
#include "eval/multiview_protocol.hpp"
#include "eval_configs.hpp"
#include "eval_leaks.hpp"
#include "eval_report.hpp"
#include "fit/fit_evaluation.hpp"
#include "fit/foot_contact.hpp"
#include "fit/view_fit.hpp"
#include "output_files.hpp"
#include "posedb/parallel_chunks.hpp"
#include "progress_bar.hpp"

namespace mocap::cli {
namespace {

using nlohmann::json;
namespace he = io::humaneva;

constexpr const char* kMonocularConfig = "full: path + SG + ray + view";

// One row of the table before pooling: which cameras, and which stage of which path.
struct Row {
  std::vector<int> cameras;  // one: monocular
  bool fitted = false;
  bool prior = false;  // several cameras, fitted: with the monocular prior
  std::string input() const { return eval::cameras_label(cameras); }
  std::string method() const {
    if (cameras.size() == 1) return fitted ? "monocular + fit (full)" : "monocular retrieval";
    if (prior) return "triangulation + tracking + fit + monocular prior (full)";
    return fitted ? "triangulation + tracking + fit (full)" : "triangulation + tracking";
  }
};

std::vector<Row> make_rows(bool fit, bool prior, bool monocular) {
  std::vector<Row> rows;
  const std::vector<std::vector<int>> sets = {{0}, {1}, {2}, {0, 1}, {0, 2}, {1, 2}, {0, 1, 2}};
  for (const auto& set : sets) {
    if (set.size() == 1 && !monocular) continue;
    for (const bool fitted : {false, true})
      if (!fitted || fit) rows.push_back({set, fitted});
    if (fit && prior && set.size() > 1) rows.push_back({set, true, true});
  }
  return rows;
}

// Poses of a monocular fit in the camera frame, placed (absolute joints).
std::vector<recon::Pose3D> placed_poses(const std::vector<fit::FittedFrame>& fitted) {
  std::vector<recon::Pose3D> out(fitted.size());
  for (std::size_t t = 0; t < fitted.size(); ++t) {
    out[t].valid = fitted[t].valid;
    out[t].joints = fitted[t].joints;
  }
  return out;
}

// A job: one camera's monocular run or one camera set's multi-view run, for a take and noise.
struct Job {
  std::size_t condition, take;
  int camera = -1;      // monocular: C1..C3 (0..2); -1: multi-view
  std::size_t set = 0;  // multi-view: index into the camera sets
};

struct Totals {
  eval::TakeScores all;
  std::map<std::string, eval::TakeScores> per_action;
  double frames = 0, own_valid = 0;  // every frame of the takes, and those the row reconstructed
};

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

double bone_std_mm(const eval::TakeScores& s) {
  eval::MultiviewResult r;
  eval::add_track_metrics(s.tracks, r);
  return r.bone_std_mm;
}

json totals_json(const Totals& t) {
  json j = scores_json(t.all.pose);
  j["own_coverage"] = t.own_valid / t.frames;
  j["bone_std_mm"] = bone_std_mm(t.all);
  if (t.all.absolute_frames > 0)
    j["mpjpe_absolute_mm"] = 1000.0 * t.all.absolute_m / static_cast<double>(t.all.absolute_frames);
  for (const auto& [action, s] : t.per_action)
    j["pa_mpjpe_per_action_mm"][action] = s.pose.pa_mpjpe();
  return j;
}

void print_row(const std::string& input, const std::string& method, const Totals& t) {
  std::cout << "| " << input << " | " << method << " | " << t.all.pose.valid << " | "
            << fixed(t.own_valid / t.frames, 3) << " | " << fixed(t.all.pose.mpjpe(), 1) << " | "
            << fixed(t.all.pose.pa_mpjpe(), 1) << " | "
            << (t.all.absolute_frames > 0
                    ? fixed(1000.0 * t.all.absolute_m / static_cast<double>(t.all.absolute_frames),
                            1)
                    : std::string("–"))
            << " | " << fixed(t.all.pose.accel(), 1) << " | " << fixed(bone_std_mm(t.all), 1)
            << " |";
  for (const auto& a : eval::kHumanEvaActions) {
    const auto found = t.per_action.find(std::string(a.label));
    std::cout << " "
              << (found == t.per_action.end() ? std::string("–")
                                              : fixed(found->second.pose.pa_mpjpe(), 1))
              << " |";
  }
  std::cout << "\n";
}

constexpr const char* kNote =
    "MPJPE: root-aligned, mean of the 14 non-root joints (the monocular protocol's); PA-MPJPE: "
    "per-frame similarity alignment, 14 non-root joints; MPJPE abs: no alignment, mean of all 15 "
    "joints, in the world (several cameras) or the camera's frame (monocular fit, placed by its "
    "camera; the retrieval alone is root-relative: –); accel: mm/frame² at the evaluation rate; "
    "bone std: per chunk and bone, mean (add_track_metrics of the multi-view protocol). Every row "
    "is scored on the frames all rows reconstructed (frames column); coverage is the row's own. "
    "The 2D given to the cameras is the monocular protocol's, noise included (same seeds). The "
    "several-camera rows see HumanEva's own joints (pelvis, thorax, headDistal) in 2D and "
    "triangulate them; the monocular rows retrieve CMU's canonical joints (mid-hip, neck, head "
    "top), so part of their error is that difference of definitions";

// What every job reads.
struct Evaluation {
  const posedb::Database* db = nullptr;
  const Config* config = nullptr;  // the monocular protocol's
  const recon::FrameBones* bones = nullptr;
  const fit::ContactDetector* contacts = nullptr;
  fit::FitOptions mono_fit;
  eval::HumanEvaMultiviewOptions multiview;
  bool fit = true;
  bool monocular = true;  // the single-camera rows
  std::vector<eval::HumanEvaSequence> sequences;
  std::vector<eval::HumanEvaTake> takes;
  std::vector<eval::Condition> conditions;
  std::vector<Row> rows;
  std::vector<std::vector<int>> sets;  // the several-camera sets, in row order

  std::size_t row(const std::vector<int>& cameras, bool fitted, bool prior = false) const {
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (rows[i].cameras == cameras && rows[i].fitted == fitted && rows[i].prior == prior)
        return i;
    throw std::logic_error("no row " + eval::cameras_label(cameras));
  }
  // Camera c's 2D of a take with the monocular protocol's noise and seed (mocap eval humaneva).
  std::vector<recon::BodyXyc> input(const Job& job, int c) const {
    const std::size_t s = takes[job.take].sequence[static_cast<std::size_t>(c)];
    return eval::noisy_input(sequences[s], conditions[job.condition],
                             1000003ull * s + job.condition);
  }
};

using Poses = std::vector<std::vector<std::vector<std::vector<recon::Pose3D>>>>;  // [n][take][row]
// Per condition and camera set: people reported besides the subject, frames missing a joint.
struct Counts {
  std::vector<std::vector<long>> extra_people, partial_frames;
};

// The monocular job: the protocol's retrieval and the monocular fit of one camera.
void run_monocular(const Evaluation& e, const Job& job,
                   std::vector<std::vector<recon::Pose3D>>& out) {
  const eval::HumanEvaSequence& s =
      e.sequences[e.takes[job.take].sequence[static_cast<std::size_t>(job.camera)]];
  recon::Matcher matcher(*e.db, e.config->match);
  recon::SequenceOptions retrieval = e.config->sequence;
  retrieval.camera = s.camera;  // the configuration turns poses onto the root's ray
  fit::FitOptions options = e.mono_fit;
  options.camera = s.camera;
  const fit::ViewFits fits = fit::reconstruct_and_fit(
      matcher, *e.bones, e.contacts, e.input(job, job.camera), retrieval, options, {e.fit, false});
  out[e.row({job.camera}, false)] = fits.retrieved;
  if (e.fit) out[e.row({job.camera}, true)] = placed_poses(fits.full);
}

Poses run_jobs(const Evaluation& e, int threads, Counts& counts) {
  std::vector<Job> jobs;
  for (std::size_t n = 0; n < e.conditions.size(); ++n)
    for (std::size_t t = 0; t < e.takes.size(); ++t) {
      if (e.monocular)
        for (int c = 0; c < he::kCameras; ++c) jobs.push_back({n, t, c, 0});
      for (std::size_t s = 0; s < e.sets.size(); ++s) jobs.push_back({n, t, -1, s});
    }
  Poses poses(e.conditions.size(),
              std::vector<std::vector<std::vector<recon::Pose3D>>>(
                  e.takes.size(), std::vector<std::vector<recon::Pose3D>>(e.rows.size())));
  counts.extra_people.assign(e.conditions.size(), std::vector<long>(e.sets.size(), 0));
  counts.partial_frames = counts.extra_people;
  std::mutex counts_mutex;
  ProgressBar bar;
  posedb::for_each_chunk(
      jobs.size(), threads,
      [&](std::size_t i) {
        const Job& job = jobs[i];
        auto& out = poses[job.condition][job.take];  // each job writes its own rows
        if (job.camera >= 0) return run_monocular(e, job, out);
        const std::vector<recon::BodyXyc> inputs[] = {e.input(job, 0), e.input(job, 1),
                                                      e.input(job, 2)};
        const auto& set = e.sets[job.set];
        const auto r =
            eval::reconstruct_take(e.takes[job.take], e.sequences, inputs, set, e.multiview);
        out[e.row(set, false)] = r.triangulated;
        if (e.fit) out[e.row(set, true)] = r.fitted;
        if (e.fit && e.multiview.prior_db) out[e.row(set, true, true)] = r.fitted_prior;
        const std::lock_guard lock(counts_mutex);
        counts.extra_people[job.condition][job.set] += r.extra_people;
        counts.partial_frames[job.condition][job.set] += r.partial_frames;
      },
      [&](std::size_t done) {
        bar.update("evaluate", static_cast<double>(done) / static_cast<double>(jobs.size()));
      });
  bar.finish();
  return poses;
}

// Every row's scores at one noise level, each take scored on the frames all rows reconstructed.
std::vector<Totals> score_rows(const Evaluation& e, const Poses& poses, std::size_t condition) {
  std::vector<Totals> totals(e.rows.size());
  for (std::size_t t = 0; t < e.takes.size(); ++t) {
    const eval::HumanEvaTake& take = e.takes[t];
    const auto& take_poses = poses[condition][t];
    std::vector<char> keep(take.truth_world.size(), 1);
    for (const auto& p : take_poses)
      for (std::size_t f = 0; f < keep.size(); ++f) keep[f] = keep[f] && p[f].valid;
    const std::string& action = e.sequences[take.sequence[0]].action;
    for (std::size_t r = 0; r < e.rows.size(); ++r) {
      const Row& row = e.rows[r];
      const bool mono = row.cameras.size() == 1;
      const auto& truth =
          mono ? e.sequences[take.sequence[static_cast<std::size_t>(row.cameras[0])]].truth_camera
               : take.truth_world;
      const eval::TakeScores s = eval::score_take(take_poses[r], truth, &keep, !mono || row.fitted);
      totals[r].all.add(s);
      totals[r].per_action[action].add(s);
      totals[r].frames += static_cast<double>(keep.size());
      for (const auto& p : take_poses[r]) totals[r].own_valid += p.valid ? 1.0 : 0.0;
    }
  }
  return totals;
}

// The rows of one camera (count 1) or of one pair (count 2) at a stage, added up.
Totals pooled(const Evaluation& e, const std::vector<Totals>& totals, bool fitted, bool prior,
              std::size_t count) {
  Totals sum;
  for (std::size_t r = 0; r < e.rows.size(); ++r) {
    if (e.rows[r].fitted != fitted || e.rows[r].prior != prior || e.rows[r].cameras.size() != count)
      continue;
    sum.all.add(totals[r].all);
    for (const auto& [a, s] : totals[r].per_action) sum.per_action[a].add(s);
    sum.frames += totals[r].frames;
    sum.own_valid += totals[r].own_valid;
  }
  return sum;
}

// One noise level's table, each camera's and each pair's rows followed by their pool.
json print_table(const Evaluation& e, const std::vector<Totals>& totals, const std::string& label) {
  std::cout << "\n### " << label
            << "\n\n| cameras | method | frames | coverage | MPJPE mm | PA-MPJPE mm | MPJPE abs "
               "mm | accel mm/f² | bone std mm | PA Walk | PA Jog | PA Box |\n"
               "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  json per_row = json::object();
  for (std::size_t r = 0; r < e.rows.size(); ++r) {
    const Row& row = e.rows[r];
    print_row(row.input(), row.method(), totals[r]);
    per_row[row.input() + ", " + row.method()] = totals_json(totals[r]);
    const bool last_single = row.cameras == std::vector<int>{2};
    const bool last_pair = row.cameras == std::vector<int>{1, 2};
    const bool with_prior = e.fit && e.multiview.prior_db && last_pair;
    if (!(last_single || last_pair) || (e.fit && !row.fitted) || (with_prior && !row.prior))
      continue;
    for (const auto& [fitted, prior] : {std::pair{false, false}, {true, false}, {true, true}}) {
      if ((fitted && !e.fit) || (prior && !with_prior)) continue;
      const Totals sum = pooled(e, totals, fitted, prior, row.cameras.size());
      const std::string input = last_single ? "each of C1, C2, C3" : "each pair";
      const std::string method = Row{row.cameras, fitted, prior}.method();
      print_row("**" + input + "**", method, sum);
      per_row[input + ", " + method] = totals_json(sum);
    }
  }
  return per_row;
}

// Comma-separated percentages.
Range noise_percentages() {
  Range range = Range::between(0.0, 100.0);
  range.list = true;
  return range;
}

}  // namespace

int humaneva_multiview_command(int argc, char** argv) {
  Args args("mocap eval humaneva-multiview --db CMU_TRAIN_DB [options]",
            "HumanEva-I Validate (S1-S3; Walk, Jog, Box) with 2 and 3 of its calibrated cameras "
            "at once\n(components/multiview: association, triangulation, tracking; then the "
            "multi-view skeleton fit),\nnext to each camera alone (the monocular protocol's "
            "retrieval, then the monocular fit), on the\nsame chunks and frames, from the "
            "ground-truth 2D with seeded noise. MPJPE, PA-MPJPE, absolute\nMPJPE, acceleration "
            "error, bone-length std; Markdown tables and every number as JSON.");
  args.option("db", "FILE",
              "pose database for the monocular rows and the prior (the CMU train split)")
      .option("data", "DIR", "HumanEva-I in the VideoPose3D format",
              "../shared/data/eval/humaneva_i_videopose3d")
      .option("json", "FILE", "where to write all numbers", "eval_humaneva_multiview.json")
      .option("threads", "N", "worker threads", "2", Range::count(1, 64))
      .option("noise", "LIST", "2D noise σ, percent of the 2D box height", "0,2",
              noise_percentages())
      .option("max-frames", "N", "frames per chunk at most, at the database rate (0 = all)", "0",
              Range::count(0, std::numeric_limits<int>::max()))
      .flag("no-fit", "triangulation and monocular retrieval only (no skeleton fits)")
      .flag("no-monocular", "the several-camera rows only (for sweeps)")
      .flag("no-prior", "no row + fit + monocular prior (the multi-view fit with --db's poses)")
      .option("prior-set", "NAME=VALUE",
              "a setting of the monocular prior (few_views_rad, two_views_rad, many_views_rad, "
              "robust_rad, max_depth_error_m, few_views_frames, few_views_reference 0/1); "
              "repeat for several",
              std::nullopt, true)
      .option("split", "NAME",
              "validate (the evaluation) or train (for choosing settings; no other split)",
              "validate")
      .flag("allow-leak",
            "evaluate even when the database holds HumanEva Validate clips (refused otherwise); "
            "the results then say so, loudly");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("db")) throw InputError("--db", "required: a pose database for the monocular rows");
  refuse_output_over_inputs({"--json", args.get("json")}, {{"--db", args.get("db")}});
  const auto started = std::chrono::steady_clock::now();
  const int threads = static_cast<int>(args.integer("threads"));
  const bool fit = !args.has("no-fit");
  const bool prior = fit && !args.has("no-prior");
  const std::string split_name = args.get("split");
  if (split_name != "validate" && split_name != "train")
    throw InputError("--split " + split_name, "expected validate or train");
  const he::Split split = split_name == "train" ? he::Split::train : he::Split::validate;
  const posedb::Database db = posedb::Database::open(args.get("db"));
  LeakCheck leaks;
  const std::string split_label = split == he::Split::train ? "Train" : "Validate";
  leaks.add(db.path(), humaneva_clips(db, split_label));
  leaks.enforce(args.has("allow-leak"), "HumanEva-I " + split_label,
                "mocap eval humaneva-multiview");

  const std::string folder = args.get("data");
  const he::Dataset data = he::load_dataset(folder);
  const auto cameras = he::load_cameras(std::filesystem::path(folder) / he::kCamerasFile);
  const double fps = db.build_info().fps;
  auto sequences = eval::humaneva_validation_sequences(data, cameras, fps, split);
  if (const long max = args.integer("max-frames"); max > 0)
    for (auto& s : sequences)
      if (s.input.size() > static_cast<std::size_t>(max)) {
        s.input.resize(static_cast<std::size_t>(max));
        s.truth_camera.resize(static_cast<std::size_t>(max));
      }
  std::vector<eval::Condition> conditions;
  for (const double percent : args.numbers("noise"))
    conditions.push_back({static_cast<float>(percent / 100.0), 0.0f});

  // The monocular protocol's configuration, and the monocular fit as humaneva-fit runs it.
  const auto configs = make_configs(db, db, fps);
  const auto config = std::find_if(configs.begin(), configs.end(),
                                   [](const Config& c) { return c.name == kMonocularConfig; });
  if (config == configs.end())
    throw std::logic_error(std::string("no monocular configuration ") + kMonocularConfig);
  const recon::FrameBones bones(db);
  const fit::ContactDetector contacts(db);
  Evaluation e;
  e.db = &db;
  e.config = &*config;
  e.bones = &bones;
  e.contacts = &contacts;
  e.mono_fit.ground = cameras.begin()->second.floor.value();  // HumanEva's world Z = 0
  e.multiview.fps = fps;
  e.multiview.fit = fit;
  e.multiview.prior_db = prior ? &db : nullptr;
  for (const std::string& setting : args.all("prior-set"))
    set_prior_option(e.multiview.prior, setting);
  e.fit = fit;
  e.sequences = std::move(sequences);
  e.takes = eval::humaneva_takes(e.sequences, cameras);
  e.conditions = std::move(conditions);
  e.monocular = !args.has("no-monocular");
  e.rows = make_rows(fit, prior, e.monocular);
  for (const Row& r : e.rows)
    if (r.cameras.size() > 1 && !r.fitted) e.sets.push_back(r.cameras);
  Counts counts;
  const Poses poses = run_jobs(e, threads, counts);

  std::size_t frames = 0;
  for (const auto& take : e.takes) frames += take.truth_world.size();
  std::cout << leaks.markdown_warning() << "## HumanEva-I " << split_label
            << ", several cameras and one\n\n"
            << e.takes.size() << " chunks (Walk, Jog, Box; S1-S3), " << frames << " frames at "
            << fps << " fps; monocular rows: " << args.get("db") << ", configuration \""
            << kMonocularConfig << "\"; several cameras: components/multiview defaults"
            << (fit ? ", multi-view fit full mode (multiview_fit_defaults)" : "")
            << (prior ? ", + monocular prior (fit::MonocularPrior) from the same database" : "")
            << "\n";
  json results = json::object();
  for (std::size_t n = 0; n < e.conditions.size(); ++n)
    results[e.conditions[n].label()] =
        print_table(e, score_rows(e, poses, n), e.conditions[n].label());
  json counts_json = json::object();
  for (std::size_t n = 0; n < e.conditions.size(); ++n)
    for (std::size_t s = 0; s < e.sets.size(); ++s)
      counts_json[e.conditions[n].label()][eval::cameras_label(e.sets[s])] = {
          {"extra_people", counts.extra_people[n][s]},
          {"partial_frames", counts.partial_frames[n][s]}};
  std::cout << "\n" << kNote << ".\n";
  json out = {{"protocol", "humaneva-multiview"},
              {"command", command_line("mocap eval humaneva-multiview", argc, argv)},
              {"git_commit", git_commit()},
              {"machine", machine_description()},
              {"database", args.get("db")},
              {"split", split_label},
              {"monocular_configuration", kMonocularConfig},
              {"evaluation_fps", fps},
              {"chunks", e.takes.size()},
              {"frames", frames},
              {"note", kNote},
              {"multiview_counts", counts_json},
              {"joint_correspondence", eval::humaneva_joint_correspondence()},
              {"leak", leaks.to_json()},
              {"results", results}};
  write_results(out, args.get("json"), started);
  return 0;
}

}  // namespace mocap::cli
