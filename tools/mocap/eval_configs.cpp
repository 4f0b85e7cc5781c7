#include "eval_configs.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>

#include "core/input_error.hpp"

namespace mocap::cli {

namespace fs = std::filesystem;

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
  Config path_sg{"path + SG, no ray",
                 "all views, Viterbi path over candidates, Savitzky-Golay (3, 11), pose as the "
                 "database camera sees it",
                 &full,
                 {},
                 base};
  path_sg.sequence.selection = recon::Selection::path;
  path_sg.sequence.smoothing = recon::Smoothing::savitzky_golay;
  configs.push_back(path_sg);
  Config ray_only = path_sg;
  ray_only.name = "path + SG + ray";
  ray_only.description =
      "all views, Viterbi path, Savitzky-Golay (3, 11), pose turned onto the root's ray";
  ray_only.align_to_ray = true;
  configs.push_back(ray_only);
  Config full_offline = ray_only;
  full_offline.name = "full: path + SG + ray + view";
  full_offline.description =
      "all views, Viterbi path, Savitzky-Golay (3, 11), view refined against the 2D pose, pose "
      "turned onto the "
      "root's ray";
  full_offline.sequence.refine_view = true;
  configs.push_back(full_offline);
  Config full_live{"full live: path + 1-Euro",
                   "all views, Viterbi path, 1-Euro (beta 0.4, fc_min 1), view refined, pose "
                   "turned onto the root's ray",
                   &full,
                   {},
                   base};
  full_live.sequence.selection = recon::Selection::path;
  full_live.sequence.smoothing = recon::Smoothing::one_euro;
  full_live.align_to_ray = true;
  full_live.sequence.refine_view = true;
  configs.push_back(full_live);
  return configs;
}

posedb::BuildOptions paper_build_options(const std::string& command) {
  posedb::BuildOptions options;
  options.views.heights_m = {1.5f};
  options.command = command;
  return options;
}

posedb::Database open_temporary_database(const posedb::DatabaseContents& contents,
                                         const std::string& tag) {
  const std::string path =
      (fs::temp_directory_path() / ("mocap-" + tag + "-" + std::to_string(::getpid()) + ".mdb"))
          .string();
  posedb::write_database(contents, path);
  posedb::Database db = posedb::Database::open(path);
  fs::remove(path);  // the mapping stays valid; nothing is left behind if the run is killed later
  return db;
}

posedb::Database open_paper_database(const std::string& given, const std::string& mocap,
                                     const std::string& command) {
  if (!given.empty()) return posedb::Database::open(given);
  std::cerr << "building the paper's yaw-only database from the train split of " << mocap << "\n";
  posedb::BuildReport report;
  const auto contents = posedb::build_database(
      posedb::split_files(mocap, "train"),
      paper_build_options(command + " (paper database: yaw-only views at 1.5 m)"), {}, report);
  return open_temporary_database(contents, "paper");
}

nlohmann::json scores_json(const eval::Scores& s) {
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

void set_prior_option(fit::MonocularPriorOptions& o, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos) throw InputError("--prior-set " + assignment, "expected NAME=VALUE");
  const std::string name = assignment.substr(0, eq);
  double value = 0.0;
  try {
    value = std::stod(assignment.substr(eq + 1));
  } catch (const std::exception&) {
    throw InputError("--prior-set " + assignment, "the value is not a number");
  }
  const std::map<std::string, double*> settings = {{"few_views_rad", &o.few_views_rad},
                                                   {"two_views_rad", &o.two_views_rad},
                                                   {"many_views_rad", &o.many_views_rad},
                                                   {"robust_rad", &o.robust_rad},
                                                   {"max_depth_error_m", &o.max_depth_error_m}};
  if (name == "few_views_reference") {
    o.few_views_reference = value != 0.0;
    return;
  }
  if (name == "few_views_frames") {
    if (!(value >= 1.0 && value <= 10000.0) || value != std::floor(value))
      throw InputError("--prior-set " + assignment, "a whole number of frames from 1 expected");
    o.few_views_frames = static_cast<int>(value);
    return;
  }
  const auto found = settings.find(name);
  if (found == settings.end())
    throw InputError("--prior-set " + assignment,
                     "unknown setting " + name +
                         " (few_views_rad, two_views_rad, many_views_rad, robust_rad, "
                         "max_depth_error_m, few_views_frames, few_views_reference)");
  *found->second = value;
}

}  // namespace mocap::cli
