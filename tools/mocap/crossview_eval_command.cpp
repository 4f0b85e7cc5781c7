// `mocap eval crossview`: cross-view consistency, the paper's §5.3 (../shared/docs/EVALUATION.md).
// Every calibrated view of the same instants is reconstructed on its own (the monocular pipeline:
// retrieval path + Savitzky-Golay + ray + view with the camera's intrinsics, then the full-
// sequence skeleton fit), each view's root-relative pose is turned into the world frame with its
// camera's rotation, and the mean per-joint distance between every pair of views is averaged over
// frames: once with the camera rotations alone ("world") and once after removing the rotation
// about the vertical axis as EVALUATION.md defines the metric ("yaw-aligned"). Data: Pose2Sim's
// balancing trial (4 cameras, OpenPose BODY_25B) and HumanEva-I Validate (Walk, Jog, Box; C1-C3,
// ground-truth 2D). The truth's own consistency (0 up to rounding) and each view's MPJPE against
// the reference are reported beside it.

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <optional>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "eval/crossview.hpp"
#include "eval/humaneva_protocol.hpp"
#include "eval/pose2sim_trial.hpp"
#include "eval_report.hpp"
#include "fit/fit_evaluation.hpp"
#include "fit/foot_contact.hpp"
#include "fit/view_fit.hpp"
#include "output_files.hpp"
#include "posedb/parallel_chunks.hpp"
#include "progress_bar.hpp"
#include "recon/layout_offsets.hpp"

namespace mocap::cli {
namespace {

using nlohmann::json;
namespace he = io::humaneva;

// One view of one multi-view sequence, ready to reconstruct.
struct ViewJob {
  std::size_t group = 0;  // the multi-view sequence it belongs to
  std::string name;       // camera name
  std::vector<recon::BodyXyc> input;
  std::vector<eval::Body> truth_camera;  // absolute, camera frame
  camera::Camera camera;                 // intrinsics and pose in the world
  bool layout_offsets = false;
};

struct Group {
  std::string dataset;  // "Pose2Sim" or "HumanEva-I"
  std::string name;
  std::vector<std::size_t> views;  // job indices, camera order
};

constexpr std::array<const char*, 3> kMethods = {"truth", "retrieval only", "+ fit, full sequence"};
constexpr glm::dvec3 kUp{0.0, 0.0, 1.0};  // both worlds are Z up

// The horizontal angle between two cameras' optical axes, degrees.
double angle_between(const camera::Camera& a, const camera::Camera& b) {
  auto axis = [](const camera::Camera& c) {
    glm::dvec3 z = c.optical_axis();
    z -= glm::dot(z, kUp) * kUp;
    return glm::normalize(z);
  };
  return std::acos(std::clamp(glm::dot(axis(a), axis(b)), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

double percentile(std::vector<double> v, double p) {
  std::erase_if(v, [](double x) { return !std::isfinite(x); });
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * (v.size() - 1) + 0.5)];
}

// Pose2Sim's trial: the reprojection check printed, one group of four views added.
json add_pose2sim(const std::string& trial_dir, const std::string& calibration, double fps,
                  std::vector<ViewJob>& jobs, std::vector<Group>& groups, bool offsets) {
  const eval::Pose2SimTrial trial = eval::load_pose2sim_trial(trial_dir, calibration);
  std::cout << "### Pose2Sim calibration check: " << trial.reference_file << " projected through "
            << calibration << " (pinhole, no distortion) onto the nearest BODY_25B detection\n\n"
            << "| camera | detections per frame | frames with the participant | median px, 21 "
               "markers | 90th pct px, 21 markers | median px, 15 body joints |\n"
               "|---|---|---:|---:|---:|---:|\n";
  json check = json::array();
  Group group{"Pose2Sim", std::filesystem::path(trial_dir).filename().string(), {}};
  for (const eval::Pose2SimView& v : trial.views) {
    const auto [lo, hi] = std::minmax_element(v.people.begin(), v.people.end());
    const double found =
        static_cast<double>(std::count_if(v.reprojection_px.begin(), v.reprojection_px.end(),
                                          [](double d) { return std::isfinite(d); }));
    const double median = percentile(v.marker_reprojection_px, 0.5),
                 p90 = percentile(v.marker_reprojection_px, 0.9),
                 body = percentile(v.reprojection_px, 0.5);
    std::cout << "| " << v.camera.name << " | " << *lo << "-" << *hi << " | " << std::fixed
              << std::setprecision(0) << found << " / " << v.reprojection_px.size() << " | "
              << std::setprecision(1) << median << " | " << p90 << " | " << body << " |\n";
    check.push_back({{"camera", v.camera.name},
                     {"median_px_markers", median},
                     {"p90_px_markers", p90},
                     {"median_px_body_joints", body},
                     {"frames", v.reprojection_px.size()},
                     {"frames_with_participant", found}});
    ViewJob job;
    job.group = groups.size();
    job.name = v.camera.name;
    job.input = eval::resample_keypoints(v.input, trial.fps, fps);
    job.truth_camera = eval::resample_bodies(v.truth_camera, trial.fps, fps);
    job.camera = v.camera;
    job.layout_offsets = offsets;
    group.views.push_back(jobs.size());
    jobs.push_back(std::move(job));
  }
  std::cout << "\nThe participant in each camera and frame is the detection whose 15 body joints "
               "lie nearest the projected reference (median over the joints); the markers columns "
               "compare that detection's BODY_25B keypoints with the 21 TRC markers.\n\n";
  groups.push_back(std::move(group));
  return check;
}

// HumanEva-I Validate: one group per chunk, its three cameras.
void add_humaneva(const std::string& folder, double fps, std::size_t max_frames,
                  std::vector<ViewJob>& jobs, std::vector<Group>& groups) {
  const he::Dataset data = he::load_dataset(folder);
  const auto cameras = he::load_cameras(std::filesystem::path(folder) / he::kCamerasFile);
  const auto sequences = eval::humaneva_validation_sequences(data, cameras, fps);
  for (std::size_t i = 0; i < sequences.size(); ++i) {
    const auto& s = sequences[i];
    if (groups.empty() || groups.back().dataset != "HumanEva-I" ||
        groups.back().name != s.subject + " " + s.chunk)
      groups.push_back({"HumanEva-I", s.subject + " " + s.chunk, {}});
    ViewJob job;
    job.group = groups.size() - 1;
    job.name = s.camera.name;
    job.input = s.input;
    job.truth_camera = s.truth_camera;
    if (max_frames > 0 && job.input.size() > max_frames) {
      job.input.resize(max_frames);
      job.truth_camera.resize(max_frames);
    }
    job.camera = s.camera;
    groups.back().views.push_back(jobs.size());
    jobs.push_back(std::move(job));
  }
}

// A view's world-frame, root-relative poses for one method.
std::vector<std::optional<eval::Body>> world_poses(const ViewJob& job, const fit::ViewFits& fits,
                                                   std::size_t method) {
  const glm::dmat3 to_world = glm::transpose(job.camera.rotation);
  std::vector<std::optional<eval::Body>> out(job.input.size());
  for (std::size_t t = 0; t < out.size(); ++t) {
    if (method == 0 && t < job.truth_camera.size())
      out[t] = eval::to_world_root_relative(job.truth_camera[t], to_world);
    if (method == 1 && t < fits.retrieved.size() && fits.retrieved[t].valid)
      out[t] = eval::to_world_root_relative(fits.retrieved[t].joints, to_world);
    if (method == 2 && t < fits.full.size() && fits.full[t].valid)
      out[t] = eval::to_world_root_relative(fits.full[t].root_relative(), to_world);
  }
  return out;
}

}  // namespace

int crossview_eval_command(int argc, char** argv) {
  Args args("mocap eval crossview --db DB [options]",
            "Cross-view consistency (the paper's §5.3): every calibrated view reconstructed on its "
            "own, the poses\nturned into the world frame, the mean per-joint distance between "
            "every pair of views (cm), before\nand after fitting; Pose2Sim's balancing trial (4 "
            "cameras) and HumanEva-I Validate (3 cameras).");
  args.option("db", "FILE", "pose database (e.g. the CMU train split)")
      .option("pose2sim", "DIR", "Pose2Sim trial folder (pose/camXX_json, pose-3d)",
              "../shared/data/eval/pose2sim_demo/S00_P00_T01_BalancingTrial")
      .option("calibration", "FILE", "Pose2Sim calibration (TOML)",
              "../shared/data/eval/pose2sim_demo/calibration/Calib_qualisys.toml")
      .option("humaneva", "DIR", "HumanEva-I in the VideoPose3D format",
              "../shared/data/eval/humaneva_i_videopose3d")
      .option("datasets", "LIST", "pose2sim, humaneva or both", "pose2sim,humaneva")
      .option("layout-offsets", "auto|off",
              "Pose2Sim: the matcher's candidates re-scored in BODY_25B's keypoints "
              "(calibration/layouts/body25b.yaml), as `mocap reconstruct` does for JSON",
              "auto")
      .option("json", "FILE", "where to write all numbers", "eval_crossview.json")
      .option("threads", "N", "worker threads", "2", Range::count(1, 64))
      .option("max-frames", "N", "HumanEva: frames per chunk at most, database rate (0 = all)", "0",
              Range::count(0, std::numeric_limits<int>::max()))
      .option("clearance", "M", "ankle height over the floor the ground term keeps", "0.07",
              Range::between(0.0, 0.5))
      .flag("no-ground", "no ground plane (default: the world's Z = 0 floor of both datasets)")
      .flag("quick", "HumanEva: the first 48 frames (2 s) of every chunk");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("db")) throw InputError("--db", "required: a pose database");
  const auto started = std::chrono::steady_clock::now();
  refuse_output_over_inputs({"--json", args.get("json")},
                            {{"--db", args.get("db")}, {"--calibration", args.get("calibration")}});
  const int threads = static_cast<int>(args.integer("threads"));
  const posedb::Database db = posedb::Database::open(args.get("db"));
  const double fps = db.build_info().fps;
  const std::string datasets = args.get("datasets");
  const bool use_offsets = args.get("layout-offsets") == "auto";
  if (!use_offsets && args.get("layout-offsets") != "off")
    throw InputError("--layout-offsets", "auto or off");
  std::optional<recon::LayoutOffsets> body25b;
  if (use_offsets) body25b = recon::resolve_layout_offsets("auto", LayoutId::body25b);

  std::vector<ViewJob> jobs;
  std::vector<Group> groups;
  json out = {
      {"protocol", "crossview"},    {"command", command_line("mocap eval crossview", argc, argv)},
      {"git_commit", git_commit()}, {"machine", machine_description()},
      {"database", args.get("db")}, {"evaluation_fps", fps}};
  std::cout << "## Cross-view consistency (the paper's §5.3)\n\n";
  if (datasets.find("pose2sim") != std::string::npos)
    out["pose2sim_calibration_check"] = add_pose2sim(args.get("pose2sim"), args.get("calibration"),
                                                     fps, jobs, groups, body25b.has_value());
  const long max_frames = args.has("quick") ? 48 : args.integer("max-frames");
  if (datasets.find("humaneva") != std::string::npos)
    add_humaneva(args.get("humaneva"), fps, static_cast<std::size_t>(std::max(0L, max_frames)),
                 jobs, groups);
  if (jobs.empty()) throw InputError("--datasets", "pose2sim, humaneva or both");

  fit::FitOptions fit_options;
  fit_options.ankle_clearance_m = args.number("clearance");
  if (!args.has("no-ground")) fit_options.ground = GroundPlane{kUp, 0.0};
  const recon::FrameBones bones(db);
  const fit::ContactDetector contacts(db);
  std::vector<fit::ViewFits> fits(jobs.size());
  ProgressBar bar;
  posedb::for_each_chunk(
      jobs.size(), threads,
      [&](std::size_t i) {
        const ViewJob& job = jobs[i];
        recon::Matcher matcher(db, {});
        if (job.layout_offsets) matcher.set_layout(body25b);
        recon::SequenceOptions retrieval;
        retrieval.fps = fps;
        retrieval.selection = recon::Selection::path;
        retrieval.smoothing = recon::Smoothing::savitzky_golay;
        retrieval.camera = job.camera;
        retrieval.refine_view = true;
        fit::FitOptions options = fit_options;
        options.camera = job.camera;  // intrinsics and its place in the world
        fits[i] = fit::reconstruct_and_fit(matcher, bones, &contacts, job.input, retrieval, options,
                                           {true, false});
      },
      [&](std::size_t done) {
        bar.update("reconstruct", static_cast<double>(done) / static_cast<double>(jobs.size()));
      });
  bar.finish();

  // Cross-view per dataset and pair (pairs are in view order within a group).
  const std::array<eval::CrossViewAlignment, 2> alignments = {
      eval::CrossViewAlignment::none, eval::CrossViewAlignment::vertical_axis};
  for (const std::string dataset : {"Pose2Sim", "HumanEva-I"}) {
    // [method][alignment] -> pairs summed over the dataset's groups
    std::array<std::array<std::vector<eval::CrossViewPair>, 2>, 3> totals;
    std::vector<std::string> names;
    std::vector<double> angles;
    std::array<eval::Scores, 3> accuracy;  // per view against the reference, summed
    std::size_t frames = 0, group_count = 0;
    for (const Group& g : groups) {
      if (g.dataset != dataset) continue;
      ++group_count;
      if (names.empty()) {
        for (std::size_t a = 0; a < g.views.size(); ++a)
          for (std::size_t b = a + 1; b < g.views.size(); ++b) {
            names.push_back(jobs[g.views[a]].name + " - " + jobs[g.views[b]].name);
            angles.push_back(angle_between(jobs[g.views[a]].camera, jobs[g.views[b]].camera));
          }
      }
      for (std::size_t m = 0; m < kMethods.size(); ++m) {
        std::vector<std::vector<std::optional<eval::Body>>> views;
        for (std::size_t v : g.views) views.push_back(world_poses(jobs[v], fits[v], m));
        for (std::size_t k = 0; k < alignments.size(); ++k)
          eval::add_pairs(totals[m][k], eval::crossview_pairs(views, kUp, alignments[k]));
      }
      for (std::size_t v : g.views) {
        frames += jobs[v].input.size();
        accuracy[1].add(eval::score(fits[v].retrieved, jobs[v].truth_camera));
        accuracy[2].add(eval::score(fit::as_poses(fits[v].full), jobs[v].truth_camera));
      }
    }
    if (group_count == 0) continue;
    std::cout << "### " << dataset << ": " << group_count << " multi-view sequence(s), " << frames
              << " view-frames at " << std::defaultfloat << std::setprecision(6) << fps
              << " fps\n\n"
              << "Mean per-joint distance between two views' reconstructions of the same "
                 "instant, cm (world: camera rotations only; yaw-aligned: the rotation about the "
                 "vertical removed, EVALUATION.md).\n\n"
              << "| pair | angle ° | frames | truth, world | retrieval, world | retrieval, "
                 "yaw-aligned | + fit, world | + fit, yaw-aligned |\n"
                 "|---|---:|---:|---:|---:|---:|---:|---:|\n";
    json jd = json::object();
    auto row = [&](const std::string& name, double angle, double count,
                   const std::array<double, 5>& cm) {
      std::cout << "| " << name << " | " << std::fixed << std::setprecision(0);
      if (std::isfinite(angle))
        std::cout << angle;
      else
        std::cout << "-";
      std::cout << " | " << count << " | " << std::setprecision(1) << cm[0] << " | " << cm[1]
                << " | " << cm[2] << " | " << cm[3] << " | " << cm[4] << " |\n";
    };
    for (std::size_t p = 0; p < names.size(); ++p) {
      const std::array<double, 5> cm = {totals[0][0][p].mean_cm(), totals[1][0][p].mean_cm(),
                                        totals[1][1][p].mean_cm(), totals[2][0][p].mean_cm(),
                                        totals[2][1][p].mean_cm()};
      row(names[p], angles[p], totals[1][0][p].frames, cm);
      jd["pairs"][names[p]] = {{"angle_deg", angles[p]},
                               {"frames_retrieval", totals[1][0][p].frames},
                               {"truth_world_cm", cm[0]},
                               {"retrieval_world_cm", cm[1]},
                               {"retrieval_yaw_aligned_cm", cm[2]},
                               {"fit_world_cm", cm[3]},
                               {"fit_yaw_aligned_cm", cm[4]}};
    }
    double pair_frames = 0;
    for (const auto& p : totals[1][0]) pair_frames += p.frames;
    const std::array<double, 5> all = {eval::mean_cm(totals[0][0]), eval::mean_cm(totals[1][0]),
                                       eval::mean_cm(totals[1][1]), eval::mean_cm(totals[2][0]),
                                       eval::mean_cm(totals[2][1])};
    row("all pairs", std::nan(""), pair_frames, all);
    jd["all_pairs"] = {{"truth_world_cm", all[0]},
                       {"retrieval_world_cm", all[1]},
                       {"retrieval_yaw_aligned_cm", all[2]},
                       {"fit_world_cm", all[3]},
                       {"fit_yaw_aligned_cm", all[4]}};
    std::cout << "\nEach view against the reference (camera frame; " << dataset
              << (dataset == "Pose2Sim" ? ": Pose2Sim's own filtered triangulation of the BODY_25B "
                                          "keypoints"
                                        : ": the mocap, HumanEva-15 joints")
              << "):\n\n| method | MPJPE mm | PA-MPJPE mm | accel err mm/f² | coverage |\n"
                 "|---|---:|---:|---:|---:|\n";
    for (std::size_t m = 1; m < kMethods.size(); ++m) {
      std::cout << "| " << kMethods[m] << " | " << std::setprecision(1) << accuracy[m].mpjpe()
                << " | " << accuracy[m].pa_mpjpe() << " | " << accuracy[m].accel() << " | "
                << std::setprecision(3) << accuracy[m].coverage() << " |\n";
      jd["per_view_accuracy"][kMethods[m]] = {{"mpjpe_mm", accuracy[m].mpjpe()},
                                              {"pa_mpjpe_mm", accuracy[m].pa_mpjpe()},
                                              {"accel_mm_per_frame2", accuracy[m].accel()},
                                              {"coverage", accuracy[m].coverage()}};
    }
    std::cout << "\n";
    jd["sequences"] = group_count;
    jd["view_frames"] = frames;
    out["results"][dataset] = jd;
  }
  std::cout << "Retrieval: path + Savitzky-Golay (3, 11) + ray + view refinement with each "
               "camera's intrinsics on "
            << args.get("db")
            << (body25b ? "; Pose2Sim candidates re-scored in BODY_25B (" + body25b->source + ")"
                        : std::string())
            << "; fit: full sequence, ground plane "
            << (fit_options.ground ? "world Z = 0" : "none") << ". The paper: 9.4 cm (135° apart) "
            << "and 6.8 cm (75°), VNect 16.4 and 15.2 cm.\n";
  write_results(out, args.get("json"), started);
  return 0;
}

}  // namespace mocap::cli
