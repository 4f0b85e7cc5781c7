// `mocap eval multiview` and `mocap eval pose2sim`: issue 19's multi-view reports. The work is in
// components/eval (multiview_protocol.hpp, pose2sim_multiview.hpp); this file parses the options,
// runs the cases and prints the tables and the JSON file (../shared/docs/EVALUATION.md).

#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <optional>
#include <tuple>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "eval/multiview_protocol.hpp"
#include "eval/pose2sim_multiview.hpp"
#include "eval_configs.hpp"
#include "eval_leaks.hpp"
#include "eval_report.hpp"
#include "output_files.hpp"
#include "posedb/builder.hpp"

namespace mocap::cli {
namespace {

using nlohmann::json;

std::vector<int> whole_numbers(const Args& args, const std::string& name) {
  std::vector<int> out;
  for (const double v : args.numbers(name)) {
    if (v < 1 || v > 64 || v != std::floor(v))
      throw InputError("--" + name, "whole numbers from 1 to 64 expected");
    out.push_back(static_cast<int>(v));
  }
  return out;
}

// The default: three one-factor sweeps around the target condition (4 views, 3 people,
// σ 2 %); --full: every combination; given lists: their combinations.
std::vector<eval::MultiviewCase> cases(const Args& args) {
  const bool full = args.has("full");
  const bool given = args.has("views") || args.has("people") || args.has("noise");
  std::vector<int> views = {2, 3, 4, 6, 8, 16}, people = {1, 2, 3, 4, 6};
  std::vector<float> noise = {0.0f, 0.01f, 0.02f, 0.05f};
  if (args.has("views")) views = whole_numbers(args, "views");
  for (const int v : views)
    if (v < 2) throw InputError("--views", "a multi-view scene needs two cameras or more");
  if (args.has("people")) people = whole_numbers(args, "people");
  if (args.has("noise")) {
    noise.clear();
    for (const double v : args.numbers("noise")) {
      if (!(v >= 0.0 && v <= 50.0)) throw InputError("--noise", "percentages from 0 to 50");
      noise.push_back(static_cast<float>(v / 100.0));
    }
  }
  std::vector<eval::MultiviewCase> out;
  const auto add = [&](int v, int p, float n) {
    for (const auto& c : out)
      if (c.views == v && c.people == p && c.noise == n) return;
    out.push_back({v, p, n});
  };
  if (full || given) {
    for (int v : views)
      for (int p : people)
        for (float n : noise) add(v, p, n);
  } else {
    for (int v : views) add(v, 3, 0.02f);
    for (int p : people) add(4, p, 0.02f);
    for (float n : noise) add(4, 3, n);
  }
  return out;
}

json result_json(const eval::MultiviewResult& r) {
  json j = {{"views", r.scene.views},
            {"people", r.scene.people},
            {"noise", r.scene.noise},
            {"method", std::string(eval::method_label(r.method))}};
  const auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  j.update({{"frames", r.frames},
            {"mpjpe_mm", number(r.score.mpjpe_mm())},
            {"pa_mpjpe_mm", number(r.pa_mpjpe_mm)},
            {"accel_error_mm_per_frame2", number(r.accel_error_mm)},
            {"bone_std_mm", number(r.bone_std_mm)},
            {"truth_bone_std_mm", number(r.truth_bone_std_mm)},
            {"person_frames", r.score.person_frames},
            {"reconstructed", r.score.reconstructed},
            {"wrong_associations", r.score.wrong_associations},
            {"false_people", r.score.false_people},
            {"duplicates", r.score.duplicates},
            {"id_switches", r.score.id_switches},
            {"coverage", r.score.coverage()},
            {"single_view_detections", r.score.single_view},
            {"cpu_s", r.cpu_s}});
  return j;
}

}  // namespace

int multiview_eval_command(int argc, char** argv) {
  Args args("mocap eval multiview [options]",
            "The virtual multi-view protocol on the held-out CMU clips (issue 19 report 2): "
            "people together in\none room, 2-16 ring cameras, degraded 2D (noise, 10 % dropped "
            "joints, 5 % outliers, false\ndetections, occlusion); the baseline (Pose2Sim's rule), "
            "ours per frame, ours + tracking,\n+ skeleton fit on all views (full and live). "
            "Default: three sweeps around\n4 views, 3 people, σ 2 % (under a minute); "
            "--full: every combination.");
  args.option("mocap", "DIR", "cmu31 folder with splits.txt (the clips of --split are used)",
              "../shared/data/mocap/cmu31")
      .option("split", "NAME",
              "heldout (the evaluation) or train (for choosing settings: the train clips of the "
              "subjects --db does not hold)",
              "heldout")
      .option("views", "LIST", "camera counts (e.g. 2,3,4,6,8,16)")
      .option("people", "LIST", "people in the room (e.g. 1,2,3,4,6)")
      .option("noise", "LIST", "2D noise σ, percent of the box height (e.g. 0,1,2,5)")
      .flag("full", "every combination of views, people and noise (default lists as above)")
      .option("frames", "N", "frame sets per case at 30 fps", "300", Range::count(3, 100000))
      .option("budget", "S", "CPU seconds at most per method and case (frames done are shown)",
              "60", Range::between(0.1, 1e6))
      .option("seed", "N", "scene placement and degradation seed", "1", Range::count(0, 1000000000))
      .option("json", "FILE", "where to write all numbers", "eval_multiview.json")
      .option("db", "FILE",
              "pose database (CMU train split): adds the row + skeleton fit + monocular prior")
      .option("prior-set", "NAME=VALUE",
              "with --db: a setting of the monocular prior (as mocap eval humaneva-multiview "
              "--help lists them), for choosing them with --split train; repeat for several",
              std::nullopt, true)
      .flag("allow-leak",
            "with --db: evaluate even when the database holds held-out CMU clips (refused "
            "otherwise); the results then say so, loudly");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const auto started = std::chrono::steady_clock::now();
  const std::string split = args.get("split");
  if (split != "heldout" && split != "train")
    throw InputError("--split " + split, "heldout or train expected");
  std::optional<posedb::Database> db;
  LeakCheck leaks;
  if (args.has("db")) {
    db.emplace(posedb::Database::open(args.get("db")));
    if (split == "heldout") leaks.add(db->path(), cmu_heldout_clips(*db, args.get("mocap")));
    leaks.enforce(args.has("allow-leak"), "the held-out CMU clips", "mocap eval multiview");
  }
  eval::MultiviewProtocolOptions options;
  options.prior_db = db ? &*db : nullptr;
  for (const std::string& setting : args.all("prior-set")) set_prior_option(options.prior, setting);
  options.frames = static_cast<int>(args.integer("frames"));
  options.budget_s = args.number("budget");
  options.seed = static_cast<std::uint64_t>(args.integer("seed"));
  // Train scenes (for choosing settings) take only the subjects the database never saw.
  std::vector<std::string> files = posedb::split_files(args.get("mocap"), split);
  if (split == "train" && db) files = cmu_clips_of_unseen_subjects(*db, files);
  if (files.empty())
    throw InputError(args.get("mocap") + "/splits.txt",
                     "no " + split + " clips" +
                         (db ? " of a subject " + args.get("db") + " does not hold" : ""));
  const auto clips = eval::load_truth(files, options.fps);
  const auto all = cases(args);
  json out = {{"protocol", "multiview"},
              {"split", split},
              {"command", command_line("mocap eval multiview", argc, argv)},
              {"git_commit", git_commit()},
              {"machine", machine_description()},
              {"clips", json::array()},
              {"frames", options.frames},
              {"dropout", options.dropout},
              {"outliers", options.outliers},
              {"false_detections", options.false_detections},
              {"database", db ? json(args.get("db")) : json(nullptr)},
              {"leak", leaks.to_json()},
              {"results", json::array()}};
  for (const auto& c : clips)
    out["clips"].push_back({{"clip", c.clip}, {"frames", c.world.size()}});
  std::vector<eval::MultiviewResult> results;
  for (std::size_t i = 0; i < all.size(); ++i) {
    std::cerr << "\r[" << i + 1 << "/" << all.size() << "] " << all[i].views << " views, "
              << all[i].people << " people, σ " << 100 * all[i].noise << " %   " << std::flush;
    for (auto& r : eval::run_multiview_case(clips, all[i], options)) {
      out["results"].push_back(result_json(r));
      results.push_back(std::move(r));
    }
  }
  std::cerr << "\n";
  std::cout << leaks.markdown_warning() << "## Multi-view, virtual scenes of the "
            << (split == "train" ? "train" : "held-out") << " CMU clips\n\n"
            << options.frames << " frame sets at 30 fps per case; 10 % joints dropped, 5 % "
            << "outlier keypoints, false detections (20 % of views and frames), occlusion; "
               "1920x1080 cameras on a 6 m ring (2 and 3 cameras 90 degrees apart). MPJPE in "
               "the world frame (no alignment); wrong associations: reconstructed person-frames "
               "with another person's or a false detection, of the person-frames seen by two "
               "views or more.\n\n"
            << eval::multiview_table(results);
  // The target condition, when it was run.
  const eval::MultiviewResult* baseline = nullptr;
  const eval::MultiviewResult* tracked = nullptr;
  const eval::MultiviewResult* fitted = nullptr;
  const eval::MultiviewResult* fitted_live = nullptr;
  for (const auto& r : results) {
    if (r.scene.views != 4 || r.scene.people != 3 || r.scene.noise != 0.02f) continue;
    if (r.method == eval::MultiviewMethod::pose2sim_rule) baseline = &r;
    if (r.method == eval::MultiviewMethod::tracking) tracked = &r;
    if (r.method == eval::MultiviewMethod::skeleton_fit) fitted = &r;
    if (r.method == eval::MultiviewMethod::skeleton_fit_live) fitted_live = &r;
  }
  if (baseline && tracked && fitted && fitted_live) {
    const double base = baseline->score.mpjpe_mm();
    std::cout << "\nTarget condition (4 views, 3 people, σ 2 %, drops and outliers): wrong "
                 "associations "
              << 100.0 * tracked->wrong_association_share() << " % (target <= 0.1 %), id switches "
              << tracked->score.id_switches << " (target 0); MPJPE (target <= 25 mm and <= 70 % "
              << "of the baseline's " << base << " mm): tracking " << tracked->score.mpjpe_mm()
              << " mm, + fit full " << fitted->score.mpjpe_mm() << " mm ("
              << 100.0 * fitted->score.mpjpe_mm() / base << " %), + fit live "
              << fitted_live->score.mpjpe_mm() << " mm ("
              << 100.0 * fitted_live->score.mpjpe_mm() / base << " %)\n";
    out["target"] = {{"wrong_association_share", tracked->wrong_association_share()},
                     {"id_switches", tracked->score.id_switches},
                     {"mpjpe_mm", tracked->score.mpjpe_mm()},
                     {"mpjpe_ratio_to_baseline", tracked->score.mpjpe_mm() / base},
                     {"fit_full_mpjpe_mm", fitted->score.mpjpe_mm()},
                     {"fit_full_ratio_to_baseline", fitted->score.mpjpe_mm() / base},
                     {"fit_live_mpjpe_mm", fitted_live->score.mpjpe_mm()},
                     {"fit_live_ratio_to_baseline", fitted_live->score.mpjpe_mm() / base}};
  }
  write_results(out, args.get("json"), started);
  return 0;
}

int pose2sim_eval_command(int argc, char** argv) {
  Args args("mocap eval pose2sim [options]",
            "Pose2Sim's demo (issue 19 report 1): our multi-view reconstruction of its BODY_25B "
            "JSON with its\ncalibration against Pose2Sim's own triangulated TRC, per marker: "
            "median and mean distance, views\nused, reprojection errors (ours and the TRC's), "
            "limb-length std over the trial, with and\nwithout the skeleton fit on all views; the "
            "hip width, and per marker the views each\ntriangulation left out and how far the "
            "fit moved the point.");
  args.option("trial", "DIR", "Pose2Sim trial folder (pose/camXX_json, pose-3d/*.trc)",
              "../shared/data/eval/pose2sim_demo/S00_P00_T01_BalancingTrial")
      .option("calibration", "FILE", "its calibration (Pose2Sim TOML)",
              "../shared/data/eval/pose2sim_demo/calibration/Calib_qualisys.toml")
      .option("frames", "N", "frames at most (0: all)", "0", Range::count(0, 10000000))
      .option("json", "FILE", "where to write all numbers", "eval_pose2sim.json");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  const auto started = std::chrono::steady_clock::now();
  const eval::Pose2SimComparison c = eval::compare_with_pose2sim(
      args.get("trial"), args.get("calibration"), static_cast<std::size_t>(args.integer("frames")));
  std::cout << "## Pose2Sim's demo: our 3D against Pose2Sim's TRC\n\n" << eval::pose2sim_table(c);
  json out = {{"protocol", "pose2sim"},
              {"command", command_line("mocap eval pose2sim", argc, argv)},
              {"git_commit", git_commit()},
              {"machine", machine_description()},
              {"trial", c.trial},
              {"reference", c.reference},
              {"frames", c.frames},
              {"trc_limb_std_mm", 1000 * eval::limb_std_m(c.trc_limb_lengths)},
              {"trc_hip_width_median_mm", 1000 * eval::median_of(c.trc_hip_width_m)},
              {"cameras", c.cameras},
              {"runs", json::array()}};
  const auto number = [](float v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  for (const auto& r : c.runs) {
    json run = {{"name", r.name},
                {"frames_with_participant", r.frames_with_participant},
                {"other_people", r.other_people},
                {"limb_std_mm", number(1000 * eval::limb_std_m(r.limb_lengths))},
                {"hip_width_median_mm", number(1000 * eval::median_of(r.hip_width_m))},
                {"hip_width_std_mm", number(1000 * eval::limb_std_m({r.hip_width_m}))},
                {"markers", json::object()}};
    for (std::size_t m = 0; m < c.markers.size(); ++m) {
      const auto& s = r.markers[m];
      run["markers"][c.markers[m]] = {
          {"median_mm", number(1000 * eval::median_of(s.distance_m))},
          {"mean_mm", number(1000 * eval::mean_of(s.distance_m))},
          {"views_used", number(eval::mean_of(s.views))},
          {"error_used_px", number(eval::mean_of(s.error_used_px))},
          {"error_all_px", number(eval::mean_of(s.error_all_px))},
          {"trc_error_all_px", number(eval::mean_of(s.trc_error_all_px))},
          {"views_left_out", s.left_out},
          {"left_out_error_median_px", number(eval::median_of(s.left_out_error_px))},
          {"from_triangulated_median_mm", number(1000 * eval::median_of(s.from_triangulated_m))}};
    }
    out["runs"].push_back(std::move(run));
  }
  write_results(out, args.get("json"), started);
  return 0;
}

}  // namespace mocap::cli
