// mocap-bench-people-rig: calibration from people (calibration/people_calibration.hpp) measured.
//
// 1. Pose2Sim's demo (../shared/data/eval/pose2sim_demo): the rig from a trial's OpenPose JSON
//    with the demo's intrinsics, against the demo's own (Qualisys) calibration once our world is
//    moved onto theirs by the similarity that best maps our camera centres onto theirs: position
//    (cm) and angle (degrees) per camera, RMS px; the aligned rig is written (--aligned) for
//    `mocap eval pose2sim --calibration`.
// 2. Virtual scenes (tests/support/people_rig_scene.hpp): CMU *held-out* walkers, each alone, 4
//    cameras on a 4.5 m ring, detector-like 2D (noise σ of the box height, 10 % of the joints
//    dropped, 2 % outliers): positions and angles against the truth after the same alignment, and
//    the MPJPE of the same triangulation (least squares over the scene's association) with our
//    rig and with the true rig. Nothing here is tuned: the options are the library's defaults.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "calibration/people_calibration.hpp"
#include "camera/rig_file.hpp"
#include "cli_args.hpp"
#include "core/input_error.hpp"
#include "eval/multiview_protocol.hpp"
#include "io/openpose_json.hpp"
#include "motion/body_mapping.hpp"
#include "motion/bvh.hpp"
#include "support/people_rig_scene.hpp"

namespace {

using namespace mocap;
namespace fs = std::filesystem;

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void print_comparison(const calibration::PeopleCalibration& found, const test::RigComparison& c,
                      const std::vector<camera::Camera>& reference) {
  std::printf(
      "| camera | position error cm | angle error deg | RMS px | keypoints used | dropped |\n"
      "|---|---:|---:|---:|---:|---:|\n");
  for (std::size_t k = 0; k < reference.size(); ++k)
    std::printf("| %s | %.1f | %.2f | %.2f | %d | %d |\n", reference[k].name.c_str(),
                100 * c.position_m[k], c.angle_deg[k], found.cameras[k].rms_px,
                found.cameras[k].observations, found.cameras[k].dropped);
  std::printf("\nsimilarity scale ours -> reference %.4f (1: our metres are theirs)\n\n",
              c.to_truth.scale);
}

void pose2sim_case(const fs::path& demo, const std::string& trial, const fs::path& aligned) {
  const fs::path calibration_file = demo / "calibration" / "Calib_qualisys.toml";
  const camera::Rig theirs = camera::read_rig(calibration_file);
  std::vector<camera::BodySequence> views;
  std::vector<std::string> sources;
  io::OpenPoseOptions json;
  json.body25 = io::Body25Choice::body25b;
  for (int k = 1; k <= 4; ++k) {
    const fs::path folder = demo / trial / "pose" / ("cam0" + std::to_string(k) + "_json");
    views.push_back(camera::body_sequence(io::read_openpose_folder(folder, json).frames));
    sources.push_back(folder.string());
  }
  const auto start = std::chrono::steady_clock::now();
  const calibration::PeopleCalibration found =
      calibration::calibrate_rig_from_people(theirs.cameras, views, sources);
  const double took = seconds_since(start);
  const test::RigComparison c = test::compare_rigs(found.rig.cameras, theirs.cameras);
  std::printf(
      "## Pose2Sim demo, %s: our rig against the demo's calibration (similarity-aligned)"
      "\n\n%d frames, %.1f s, overall RMS %.2f px, person height %.3f m (the scale's)\n\n",
      trial.c_str(), found.frames_used, took, found.rms_px, found.height_m);
  print_comparison(found, c, theirs.cameras);
  if (!aligned.empty()) {
    camera::Rig out = theirs;
    for (std::size_t k = 0; k < out.cameras.size(); ++k) out.cameras[k] = c.aligned[k];
    camera::write_rig(aligned, out);
    std::printf("wrote %s (our cameras in the demo's world)\n\n", aligned.string().c_str());
  }
}

double mpjpe_mm(const std::vector<std::vector<eval::Body>>& found, const test::PeopleRigScene& s) {
  double sum = 0;
  long n = 0;
  for (std::size_t f = 0; f < s.people.size(); ++f)
    for (std::size_t p = 0; p < s.people[f].size(); ++p) {
      if (!s.people[f][p]) continue;
      for (int j = 0; j < kBodyJoints; ++j) {
        const glm::vec3& a = found[f][p][static_cast<std::size_t>(j)];
        if (!std::isfinite(a.x)) continue;
        sum += glm::distance(a, (*s.people[f][p])[static_cast<std::size_t>(j)]);
        ++n;
      }
    }
  return n ? 1000 * sum / n : std::nan("");
}

// The standing height of the subject of a cgspeed file, from its reference T-pose.
double stature_of(const std::string& file) {
  const motion::Clip clip = motion::read_bvh(file);
  return motion::reference_stature_m(clip, motion::map_to_body(clip.skeleton, file));
}

// true_height: each walker alone is given its own standing height (--height) instead of the
// canonical body's (the walkers together have no one height: left out).
void virtual_cases(const fs::path& cmu, int frames, const std::vector<double>& noises,
                   bool together_only, bool true_height) {
  const std::vector<std::string> clips = {"02_01.bvh", "07_01.bvh", "07_05.bvh", "07_12.bvh"};
  std::vector<std::string> files;
  for (const auto& c : clips) files.push_back((cmu / c).string());
  const std::vector<eval::TruthSequence> truth = eval::load_truth(files, 30.0);
  std::printf(
      "## Virtual scenes: CMU held-out walkers, 4 cameras, %d frames at 30 fps\n\n"
      "| clip | noise σ | position error cm (max) | angle error deg (max) | RMS px | scale "
      "| MPJPE true rig mm | MPJPE our rig mm | difference mm | s |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
      frames);
  // Each walker alone, then the first three together (people hiding each other, a false
  // detection in a fifth of the views' frames).
  for (std::size_t i = 0; i <= truth.size(); ++i)
    for (double noise : noises) {
      const bool together = i == truth.size();
      if (together_only && !together) continue;
      if (true_height && together) continue;
      std::vector<eval::ScenePerson> people(together ? 3 : 1);
      for (std::size_t p = 0; p < people.size(); ++p) people[p].motion = &truth[together ? p : i];
      eval::spread_people(people, frames, 2.0f, 1.0f, 1);
      eval::SceneDegradation d;
      d.noise = static_cast<float>(noise);
      d.dropout = 0.1f;
      d.outliers = 0.02f;
      d.occlusion = together;
      d.false_detections = together ? 0.2f : 0.0f;
      const test::PeopleRigScene s = test::make_people_rig_scene(people, 4, frames, d, 11 + i);
      calibration::PeopleCalibrationOptions options;
      if (true_height) options.height_m = stature_of(files[i]);
      const std::string label =
          together ? "3 walkers together"
          : true_height
              ? truth[i].clip + " (--height " + std::to_string(options.height_m).substr(0, 5) + ")"
              : truth[i].clip;
      std::vector<camera::Camera> intrinsics = s.truth;
      for (camera::Camera& c : intrinsics) c.rotation = glm::dmat3(1.0), c.translation = {};
      std::vector<std::string> sources = {"view_1", "view_2", "view_3", "view_4"};
      const auto start = std::chrono::steady_clock::now();
      try {
        const calibration::PeopleCalibration found =
            calibration::calibrate_rig_from_people(intrinsics, s.views, sources, options);
        const double took = seconds_since(start);
        const test::RigComparison c = test::compare_rigs(found.rig.cameras, s.truth);
        double position = 0, angle = 0;
        for (std::size_t k = 0; k < 4; ++k)
          position = std::max(position, c.position_m[k]), angle = std::max(angle, c.angle_deg[k]);
        const double with_truth = mpjpe_mm(test::triangulate_scene(s.truth, s), s);
        const double with_ours = mpjpe_mm(test::triangulate_scene(c.aligned, s), s);
        std::printf("| %s | %.3f | %.1f | %.2f | %.2f | %.3f | %.1f | %.1f | %+.1f | %.1f |\n",
                    label.c_str(), noise, 100 * position, angle, found.rms_px, c.to_truth.scale,
                    with_truth, with_ours, with_ours - with_truth, took);
      } catch (const std::exception& e) {
        std::printf("| %s | %.3f | refused: %s |\n", label.c_str(), noise, e.what());
      }
      std::fflush(stdout);
    }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace mocap;
  cli::Args args("mocap-bench-people-rig [options]",
                 "Calibration from people on Pose2Sim's demo and on virtual scenes of CMU held-out "
                 "walkers (tables: Markdown).");
  args.option("pose2sim", "DIR", "Pose2Sim's demo folder", "../shared/data/eval/pose2sim_demo")
      .option("trial", "NAME", "the demo trial calibrated from", "S00_P00_T01_BalancingTrial")
      .option("aligned", "FILE", "write our demo rig moved into the demo's world here")
      .option("cmu", "DIR", "the cmu31 folder", "../shared/data/mocap/cmu31")
      .option("frames", "N", "frames per virtual scene", "150", cli::Range::count(20))
      .option("noise", "LIST", "noise σ of the virtual 2D, fractions of the box height",
              "0.01,0.02", cli::Range::positive_list())
      .flag("skip-virtual", "only the demo")
      .flag("skip-demo", "only the virtual scenes")
      .flag("together-only", "of the virtual scenes, only the walkers together")
      .flag("true-height",
            "give each walker alone its own standing height (its file's T-pose) as --height");
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  try {
    if (!args.has("skip-demo"))
      pose2sim_case(args.get("pose2sim"), args.get("trial"),
                    args.has("aligned") ? fs::path(args.get("aligned")) : fs::path());
    if (!args.has("skip-virtual"))
      virtual_cases(args.get("cmu"), static_cast<int>(args.integer("frames")),
                    args.numbers("noise"), args.has("together-only"), args.has("true-height"));
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-people-rig: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
