// `mocap eval humaneva-fit`: HumanEva-I Validate with its cameras, before and after the skeleton
// fitting (issue 7), in one run. Every Validate chunk (Walk, Jog, Box) through C1-C3: the
// ground-truth 2D reconstructed by the retrieval (path + Savitzky-Golay + ray + view, the camera's
// approximate intrinsics), then fitted over the whole sequence and live (fixed lag), with the
// true floor (world Z = 0) as the ground plane through the camera's pose. Per action and overall:
// MPJPE root-aligned, MPJPE absolute (camera frame, no alignment), PA-MPJPE, root error.

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "eval/humaneva_protocol.hpp"
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

// Root-aligned scores (eval::Scores) plus the absolute ones of placed joints.
struct Result {
  eval::Scores pose;
  double placed = 0;      // frames with absolute joints
  double absolute_m = 0;  // Σ over those frames of the mean distance of all 15 joints
  double root_m = 0;      // Σ root distance
  void add(const Result& o) {
    pose.add(o.pose);
    placed += o.placed;
    absolute_m += o.absolute_m;
    root_m += o.root_m;
  }
  double absolute_mm() const { return 1000.0 * absolute_m / placed; }
  double root_mm() const { return 1000.0 * root_m / placed; }
};

Result score(const std::vector<fit::FittedFrame>& frames, const std::vector<recon::Pose3D>& poses,
             const std::vector<eval::Body>& truth) {
  Result r;
  r.pose = eval::score(poses, truth);
  for (std::size_t t = 0; t < frames.size() && t < truth.size(); ++t) {
    if (!frames[t].valid) continue;
    double sum = 0;
    for (int j = 0; j < kBodyJoints; ++j) sum += glm::distance(frames[t].joints[j], truth[t][j]);
    r.placed += 1;
    r.absolute_m += sum / kBodyJoints;
    r.root_m += glm::distance(frames[t].root(), truth[t][index(Joint::root)]);
  }
  return r;
}

const std::vector<std::string> kMethods = {"retrieval only", "+ fit, full sequence", "+ fit, live"};

json result_json(const Result& r) {
  json j = scores_json(r.pose);
  j["mpjpe_absolute_mm"] = r.absolute_mm();
  j["root_error_mm"] = r.root_mm();
  j["placed_frames"] = r.placed;
  return j;
}

}  // namespace

int humaneva_fit_command(int argc, char** argv) {
  Args args("mocap eval humaneva-fit --db DB [options]",
            "HumanEva-I Validate (Walk, Jog, Box; C1-C3, ground-truth 2D) with its cameras, "
            "before and after the\nskeleton fitting: MPJPE root-aligned and absolute (camera "
            "frame), PA-MPJPE, root error.");
  args.option("db", "FILE", "pose database (e.g. the CMU train split)")
      .option("data", "DIR", "HumanEva-I in the VideoPose3D format",
              "../shared/data/eval/humaneva_i_videopose3d")
      .option("json", "FILE", "where to write all numbers", "eval_humaneva_fit.json")
      .option("threads", "N", "worker threads", "2", Range::count(1, 64))
      .option("max-frames", "N", "frames per chunk at most, at the database rate (0 = all)", "0",
              Range::count(0, std::numeric_limits<int>::max()))
      .option("noise", "F", "2D Gaussian noise, fraction of the 2D box height", "0",
              Range::between(0.0, 1.0))
      .option("lag", "N", "live fit: frames of delay", "3", Range::count(0, 100))
      .option("clearance", "M", "ankle height over the floor the ground term keeps", "0.07",
              Range::between(0.0, 0.5))
      .flag("no-ground", "no ground plane (default: HumanEva's floor, world Z = 0)")
      .flag("quick", "the first 48 frames (2 s) of every chunk")
      .flag("allow-leak",
            "evaluate even when the database holds HumanEva Validate clips (refused otherwise); "
            "the results then say so, loudly");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("db")) throw InputError("--db", "required: a pose database");
  refuse_output_over_inputs({"--json", args.get("json")}, {{"--db", args.get("db")}});
  const auto started = std::chrono::steady_clock::now();
  const int threads = static_cast<int>(args.integer("threads"));
  const posedb::Database db = posedb::Database::open(args.get("db"));
  LeakCheck leaks;
  leaks.add(db.path(), humaneva_clips(db, "Validate"));
  leaks.enforce(args.has("allow-leak"), "HumanEva-I Validate", "mocap eval humaneva-fit");
  const std::string folder = args.get("data");
  const he::Dataset data = he::load_dataset(folder);
  const auto cameras = he::load_cameras(std::filesystem::path(folder) / he::kCamerasFile);
  const double fps = db.build_info().fps;
  auto sequences = eval::humaneva_validation_sequences(data, cameras, fps);
  long max_frames = args.integer("max-frames");
  if (args.has("quick")) max_frames = 48;
  if (max_frames > 0)
    for (auto& s : sequences)
      if (s.input.size() > static_cast<std::size_t>(max_frames)) {
        s.input.resize(max_frames);
        s.truth_camera.resize(max_frames);
      }
  eval::Condition condition;
  condition.noise = static_cast<float>(args.number("noise"));

  const recon::FrameBones bones(db);
  const fit::ContactDetector contacts(db);
  fit::FitOptions fit_options;
  fit_options.lag = static_cast<int>(args.integer("lag"));
  fit_options.ankle_clearance_m = args.number("clearance");
  // HumanEva's world is Z up with the floor at Z = 0 (the rigs' floor); each camera's pose
  // carries it into its view.
  if (!args.has("no-ground")) fit_options.ground = cameras.begin()->second.floor.value();

  std::vector<std::array<Result, 3>> results(sequences.size());
  ProgressBar bar;
  posedb::for_each_chunk(
      sequences.size(), threads,
      [&](std::size_t i) {
        const eval::HumanEvaSequence& s = sequences[i];
        recon::Matcher matcher(db, {});
        recon::SequenceOptions retrieval;
        retrieval.fps = fps;
        retrieval.selection = recon::Selection::path;
        retrieval.smoothing = recon::Smoothing::savitzky_golay;
        retrieval.camera = s.camera;
        retrieval.refine_view = true;
        fit::FitOptions options = fit_options;
        options.camera = s.camera;  // intrinsics and its place in the world
        std::vector<recon::BodyXyc> input = s.input;
        eval::InputNoise noise(1000003ull * i);
        for (auto& frame : input) noise.apply(condition, frame);
        const fit::ViewFits fits =
            fit::reconstruct_and_fit(matcher, bones, &contacts, input, retrieval, options);
        results[i][0] = score(fits.placed, fits.retrieved, s.truth_camera);
        results[i][1] = score(fits.full, fit::as_poses(fits.full), s.truth_camera);
        results[i][2] = score(fits.live, fit::as_poses(fits.live), s.truth_camera);
      },
      [&](std::size_t done) {
        bar.update("evaluate", static_cast<double>(done) / static_cast<double>(sequences.size()));
      });
  bar.finish();

  std::map<std::pair<std::string, std::string>, Result> cells;  // (method, action)
  std::size_t frames = 0;
  for (std::size_t i = 0; i < sequences.size(); ++i) {
    frames += sequences[i].input.size();
    for (std::size_t m = 0; m < kMethods.size(); ++m) {
      cells[{kMethods[m], sequences[i].action}].add(results[i][m]);
      cells[{kMethods[m], "all"}].add(results[i][m]);
    }
  }
  std::vector<std::string> actions;
  for (const auto& a : eval::kHumanEvaActions) actions.emplace_back(a.label);
  actions.emplace_back("all");

  std::cout << leaks.markdown_warning()
            << "## HumanEva-I Validate with its cameras, before and after fitting\n\n"
            << sequences.size() << " sequences (chunk x camera), " << frames << " frames at " << fps
            << " fps; database " << args.get("db") << "; noise " << condition.label()
            << "; live lag " << fit_options.lag << "; ground plane "
            << (fit_options.ground ? "world Z = 0" : "none") << ", ankle clearance "
            << fit_options.ankle_clearance_m << " m\n\n"
            << "| method | action | MPJPE mm | MPJPE abs mm | PA-MPJPE mm | root err mm | accel "
               "err mm/f² | coverage |\n|---|---|---:|---:|---:|---:|---:|---:|\n";
  json table = json::object();
  for (const auto& m : kMethods) {
    for (const auto& a : actions) {
      const Result& r = cells[{m, a}];
      std::cout << "| " << m << " | " << a << " | " << std::fixed << std::setprecision(1)
                << r.pose.mpjpe() << " | " << r.absolute_mm() << " | " << r.pose.pa_mpjpe() << " | "
                << r.root_mm() << " | " << r.pose.accel() << " | " << std::setprecision(3)
                << r.pose.coverage() << " |\n";
      table[m][a] = result_json(r);
    }
  }
  const char* note =
      "MPJPE: root-aligned, mean of the 14 non-root joints; MPJPE abs: no alignment, camera "
      "frame, mean of all 15 joints (retrieval only: the retrieved pose at its closed-form "
      "translation); root error: the root's distance in the camera frame. The truth's root is "
      "HumanEva's pelvis (torsoDistal), its neck the thorax, its head headDistal; the "
      "reconstruction's are the canonical mid-hip, neck and head top, so part of every number "
      "is that difference of definitions";
  std::cout << "\n" << note << ".\n";
  json out = {{"protocol", "humaneva-fit"},
              {"command", command_line("mocap eval humaneva-fit", argc, argv)},
              {"git_commit", git_commit()},
              {"machine", machine_description()},
              {"database", args.get("db")},
              {"evaluation_fps", fps},
              {"noise", condition.label()},
              {"lag", fit_options.lag},
              {"ground", fit_options.ground ? "world Z = 0" : "none"},
              {"ankle_clearance_m", fit_options.ankle_clearance_m},
              {"sequences", sequences.size()},
              {"frames", frames},
              {"note", note},
              {"joint_correspondence", eval::humaneva_joint_correspondence()},
              {"leak", leaks.to_json()},
              {"results", table}};
  write_results(out, args.get("json"), started);
  return 0;
}

}  // namespace mocap::cli
