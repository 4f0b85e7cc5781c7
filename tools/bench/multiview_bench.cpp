// `mocap-bench-multiview`: speed of association + triangulation + tracking (components/multiview)
// on one core, in frame sets per second (one frame set = every view's detections of one instant),
// for 4 and 16 views with 6 people, ours beside Pose2Sim's triangulation rule in the same pipeline
// and ours without tracking. The input is a virtual scene (eval/multiview_scene.hpp) of CMU *train*
// clips, rendered beforehand at the target condition (σ 2 % of the box height, 10 %
// joints dropped, 5 % outlier keypoints, false detections, occlusion); only process() is timed.
// Variants run interleaved; medians over the passes are reported, with the quality of the last
// pass beside (the speed of a wrong answer is no use). The live multi-view skeleton fit
// (components/fit) is timed alone on our reconstruction's tracks, and --quality adds its accuracy
// as column (iv).

#include <time.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli_args.hpp"
#include "core/input_error.hpp"
#include "eval/multiview_scene.hpp"
#include "fit/scene_fit.hpp"
#include "multiview/rig_reconstruction.hpp"
#include "posedb/builder.hpp"

namespace {

using namespace mocap;
using Clock = std::chrono::steady_clock;

// CPU time of this thread: on a machine shared with other work, wall time counts the waits for a
// core; both are reported.
double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Six train clips of five subjects (walking about, jumps and kicks, the playground).
const std::vector<std::string> kClips = {"09_12.bvh", "91_13.bvh", "86_01.bvh",
                                         "03_03.bvh", "01_01.bvh", "03_04.bvh"};
constexpr double kFps = 30.0;

struct Variant {
  std::string name;
  multiview::ReconstructionOptions options;
};

struct Scene {
  int views = 0;
  std::vector<camera::Camera> rig;
  std::vector<eval::SceneFrame> frames;
  std::vector<multiview::FrameObservations> input;
  std::vector<multiview::ViewGeometry> geometry;
};

struct Pass {
  double frame_sets_per_s = 0.0;  // per second of this thread's CPU time
  double frame_sets_per_wall_s = 0.0;
  long frames = 0;
  eval::SceneScore score;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

std::vector<eval::TruthSequence> load_clips(const std::string& folder) {
  const std::vector<std::string> train = posedb::split_files(folder, "train");
  std::vector<std::string> files;
  for (const std::string& clip : kClips) {
    const std::string path = (std::filesystem::path(folder) / clip).string();
    if (std::find(train.begin(), train.end(), path) == train.end()) {
      throw InputError(folder, clip +
                                   " is not in the train split (splits.txt); the benchmark "
                                   "uses train clips only");
    }
    files.push_back(path);
  }
  return eval::load_truth(files, kFps);
}

std::vector<eval::ScenePerson> place_people(const std::vector<eval::TruthSequence>& clips,
                                            int count, int frames) {
  std::vector<eval::ScenePerson> people;
  for (int i = 0; i < count; ++i) {
    eval::ScenePerson p;
    p.motion = &clips[static_cast<std::size_t>(i) % clips.size()];
    p.first_frame = 60 + 400 * (i / static_cast<int>(clips.size()));
    people.push_back(p);
  }
  if (!eval::spread_people(people, frames, 2.5f, 0.5f, 1)) {
    std::cerr << "mocap-bench-multiview: note: some people come closer than 0.5 m\n";
  }
  return people;
}

// `views` cameras of a ring of max(views, 4): two are 90 degrees apart, as a two-camera rig is set
// up (opposite cameras see depth along their axis poorly).
Scene render(const std::vector<eval::ScenePerson>& people, int views, int frames, float noise) {
  Scene s;
  s.views = views;
  auto rig = eval::ring_rig(std::max(views, 4), 6.0, 1.6, 0.9, {0.0, 1.0, 0.0}, eval::Image{});
  rig.resize(static_cast<std::size_t>(views));
  for (const auto& c : rig) s.geometry.push_back(multiview::from_camera(c));
  s.rig = rig;
  eval::SceneRenderer renderer(rig, 1);
  eval::SceneDegradation d;
  d.noise = noise;
  d.dropout = 0.10f;
  d.outliers = 0.05f;
  d.false_detections = 0.2f;
  for (int f = 0; f < frames; ++f) {
    s.frames.push_back(renderer.render(people, f, d));
    eval::SceneRenderer::to_observations(s.frames.back(), s.input.emplace_back());
  }
  return s;
}

// One pass over the scene with a fresh reconstructor; stops early after `budget_s` (Pose2Sim's
// rule can take seconds per frame set at 16 views).
Pass run(const Scene& scene, const Variant& variant, int people, double budget_s) {
  multiview::ReconstructionOptions options = variant.options;
  options.tracker.fps = kFps;
  multiview::MultiViewReconstructor reconstructor(scene.geometry, multiview::KeypointSet::body15(),
                                                  options);
  eval::SceneScorer scorer(people);
  double cpu = 0.0, wall = 0.0;
  long frames = 0;
  for (std::size_t f = 0; f < scene.input.size() && cpu < budget_s; ++f) {
    const auto start = Clock::now();
    const double start_cpu = thread_cpu_s();
    const multiview::FrameResult& result =
        reconstructor.process(scene.input[f], static_cast<std::int64_t>(f));
    cpu += thread_cpu_s() - start_cpu;
    wall += std::chrono::duration<double>(Clock::now() - start).count();
    ++frames;
    scorer.add(scene.frames[f], result);
  }
  return {static_cast<double>(frames) / cpu, static_cast<double>(frames) / wall, frames,
          scorer.score()};
}

// Our reconstruction (with tracking) of the whole scene, then the skeleton fit of every track
// (live: fixed lag, or full), scored like the triangulation; the fit's CPU time alone.
struct FitPass {
  double frame_sets_per_s = 0.0;  // the fit alone, per second of this thread's CPU time
  eval::SceneScore score;
  double mean_iterations = 0.0;
};

// `--fit-set NAME=VALUE`: a weight or setting of the multi-view fit, for sweeps.
void set_fit_option(fit::MultiViewFitOptions& o, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos) throw InputError("--fit-set " + assignment, "expected NAME=VALUE");
  const std::string name = assignment.substr(0, eq);
  const double value = std::stod(assignment.substr(eq + 1));
  fit::FitWeights& w = o.fit.weights;
  const std::map<std::string, double*> fields = {
      {"reprojection", &w.reprojection}, {"robust", &w.robust},
      {"prior_rad", &w.prior_rad},       {"translation_prior_m", &w.translation_prior_m},
      {"bone_accel_m", &w.bone_accel_m}, {"root_accel_m", &w.root_accel_m},
      {"bone_prior_m", &w.bone_prior_m}, {"body_scale", &w.body_scale},
      {"symmetry_m", &w.symmetry_m},     {"velocity_m", &w.bone_velocity_m},
      {"knee_limit", &w.knee_limit},     {"ground_m", &w.ground_m}};
  if (name == "lag") {
    o.fit.lag = static_cast<int>(value);
  } else if (name == "live_iterations") {
    o.fit.live_iterations = static_cast<int>(value);
  } else if (name == "iterations") {
    o.fit.max_iterations = static_cast<int>(value);
  } else if (name == "bone_frames") {
    o.bone_frames = static_cast<int>(value);
  } else if (const auto it = fields.find(name); it != fields.end()) {
    *it->second = value;
    if (name == "velocity_m") w.root_velocity_m = value;
  } else {
    throw InputError("--fit-set " + assignment, "unknown fit parameter " + name);
  }
}

FitPass run_fit(const Scene& scene, const Variant& ours, int people, bool live,
                const std::vector<std::string>& fit_settings) {
  multiview::ReconstructionOptions options = ours.options;
  options.tracker.fps = kFps;
  multiview::MultiViewReconstructor reconstructor(scene.geometry, multiview::KeypointSet::body15(),
                                                  options);
  std::vector<multiview::FrameResult> results;
  for (std::size_t f = 0; f < scene.input.size(); ++f)
    results.push_back(reconstructor.process(scene.input[f], static_cast<std::int64_t>(f)));
  fit::MultiViewFitOptions fit_options;
  fit_options.cameras = scene.rig;
  fit_options.fit = fit::multiview_fit_defaults();
  fit_options.fit.ground = GroundPlane{{0.0, 1.0, 0.0}, 0.0};  // the scene's floor, y up
  for (const std::string& s : fit_settings) set_fit_option(fit_options, s);
  const double start = thread_cpu_s();
  const fit::TrackFits fits = fit::fit_tracks(scene.input, results, fit_options, live);
  const double cpu = thread_cpu_s() - start;
  eval::SceneScorer scorer(people);
  for (std::size_t f = 0; f < scene.frames.size(); ++f) scorer.add(scene.frames[f], results[f]);
  return {
      static_cast<double>(scene.input.size()) / cpu, scorer.score(),
      fits.stats.solves > 0 ? static_cast<double>(fits.stats.iterations) / fits.stats.solves : 0.0};
}

// `--set NAME=VALUE`: a parameter of the reconstruction, for sweeps.
void set_option(multiview::ReconstructionOptions& o, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos) throw InputError("--set " + assignment, "expected NAME=VALUE");
  const std::string name = assignment.substr(0, eq);
  const float value = std::stof(assignment.substr(eq + 1));
  const std::map<std::string, float*> fields = {
      {"pair_gate_m", &o.pair_gate_m},
      {"member_gate_m", &o.member_gate_m},
      {"attach_gate_m", &o.attach_gate_m},
      {"size_tolerance", &o.size_tolerance},
      {"min_view_fraction", &o.min_view_fraction},
      {"occlusion_margin_m", &o.occlusion_margin_m},
      {"outlier_m", &o.triangulation.robust.outlier_m},
      {"noise_factor", &o.triangulation.noise_factor},
      {"noise_ceiling_m", &o.triangulation.noise_ceiling_m},
      {"keep_pair", &o.rays.keep_pair},
      {"keep_point", &o.rays.keep_point},
      {"cap_m", &o.rays.cap_m},
      {"gate_m", &o.tracker.gate_m},
      {"velocity_smoothing", &o.tracker.velocity_smoothing},
      {"sigma_learning", &o.tracker.sigma_learning},
  };
  if (name == "prior") {
    o.tracker.prior = value != 0.0f;
  } else if (name == "pair_search_views") {
    o.triangulation.robust.pair_search_views = static_cast<int>(value);
  } else if (const auto it = fields.find(name); it != fields.end()) {
    *it->second = value;
  } else {
    throw InputError("--set " + assignment, "unknown parameter " + name);
  }
}

std::vector<Variant> variants(const std::vector<std::string>& settings) {
  std::vector<Variant> v(3);
  v[0].name = "ours (association + robust triangulation + tracking)";
  v[1].name = "ours without tracking (cold association every frame)";
  v[1].options.tracking = false;
  v[2].name = "baseline: Pose2Sim's rule (+ our association and tracking)";
  v[2].options.triangulation.method = multiview::TriangulationMethod::pose2sim;
  for (Variant& variant : v) {
    for (const std::string& s : settings) set_option(variant.options, s);
  }
  return v;
}

// Accuracy per camera count and 2D noise, the other degradations at the target condition.
void quality(const std::vector<eval::ScenePerson>& people, const std::vector<int>& view_counts,
             const std::vector<float>& noises, int frames, const std::vector<Variant>& configs,
             bool with_fit, const std::vector<std::string>& fit_settings) {
  std::cout << "## Multi-view accuracy on virtual scenes of CMU train clips\n\n"
            << people.size() << " people, " << frames
            << " frames at 30 fps, 10 % joints dropped, 5 % outlier keypoints, false "
               "detections, occlusion; 1920x1080 cameras on a 6 m ring (2 and 3 cameras: "
               "90 degrees apart)\n\n"
            << "| views | σ | configuration | MPJPE mm | joints per person | wrong associations "
               "| id switches | coverage | single-view detections |\n"
            << "|---:|---:|---|---:|---:|---:|---:|---:|---:|\n";
  for (const int views : view_counts) {
    for (const float noise : noises) {
      const Scene scene = render(people, views, frames, noise);
      std::vector<std::pair<std::string, eval::SceneScore>> rows;
      for (const Variant& v : configs)
        rows.emplace_back(v.name, run(scene, v, static_cast<int>(people.size()), 1e9).score);
      if (with_fit) {
        for (const bool live : {true, false})
          rows.emplace_back(
              live ? "(iv) ours + skeleton fit, live (lag 3)" : "(iv) ours + skeleton fit, full",
              run_fit(scene, configs[0], static_cast<int>(people.size()), live, fit_settings)
                  .score);
      }
      for (const auto& [name, s] : rows) {
        std::cout << "| " << views << " | " << std::setprecision(0) << std::fixed << 100 * noise
                  << " % | " << name << " | " << std::setprecision(1) << s.mpjpe_mm() << " | "
                  << std::setprecision(2)
                  << (s.reconstructed > 0 ? static_cast<double>(s.joints) / s.reconstructed : 0.0)
                  << " | " << s.wrong_associations << " / " << s.person_frames << " | "
                  << s.id_switches << " | " << std::setprecision(3) << s.coverage() << " | "
                  << s.single_view << " |\n";
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  cli::Args args("mocap-bench-multiview [options]",
                 "Frame sets per second of association + triangulation + tracking on one core.");
  args.option("mocap", "DIR", "cmu31 folder with splits.txt", "../shared/data/mocap/cmu31")
      .option("people", "N", "people in the scene", "6")
      .option("views", "N",
              "camera counts to run (repeat the option; default 4 and 16, with "
              "--quality 2 3 4 6 8 16)",
              std::nullopt, true)
      .option("frames", "N", "frame sets per scene (30 fps)", "300")
      .option("repeats", "N", "interleaved passes; medians are reported", "5")
      .option("budget", "S", "CPU seconds at most per pass and variant", "3")
      .flag("quality", "accuracy per camera count and 2D noise instead of speed")
      .option("noise", "S",
              "with --quality: 2D noise σ as a fraction of the box height (repeat the "
              "option; default 0, 0.01, 0.02, 0.05)",
              std::nullopt, true)
      .flag("no-fit", "leave out the multi-view skeleton fit (its speed row, its quality rows)")
      .option("fit-set", "NAME=VALUE",
              "a multi-view fit parameter (repeatable): reprojection, robust, prior_rad, "
              "translation_prior_m, bone_accel_m, root_accel_m, bone_prior_m, body_scale, "
              "symmetry_m, velocity_m, knee_limit, ground_m, lag, live_iterations, iterations, "
              "bone_frames",
              std::nullopt, true)
      .option("set", "NAME=VALUE",
              "a reconstruction parameter for every configuration (repeatable): pair_gate_m, "
              "member_gate_m, attach_gate_m, size_tolerance, min_view_fraction, "
              "occlusion_margin_m, outlier_m, noise_factor, noise_ceiling_m, keep_pair, "
              "keep_point, cap_m, gate_m, velocity_smoothing, sigma_learning, prior (0/1), "
              "pair_search_views",
              std::nullopt, true);
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  try {
    const auto clips = load_clips(args.get("mocap"));
    const int people = static_cast<int>(args.integer("people"));
    const int frame_count = static_cast<int>(args.integer("frames"));
    const auto placed = place_people(clips, people, frame_count);
    std::vector<int> view_counts;
    for (const std::string& v : args.all("views")) view_counts.push_back(std::stoi(v));
    const std::vector<Variant> configs = variants(args.all("set"));
    const std::vector<std::string> fit_settings = args.all("fit-set");
    if (args.has("quality")) {
      if (view_counts.empty()) view_counts = {2, 3, 4, 6, 8, 16};
      std::vector<float> noises;
      for (const std::string& n : args.all("noise")) noises.push_back(std::stof(n));
      if (noises.empty()) noises = {0.0f, 0.01f, 0.02f, 0.05f};
      quality(placed, view_counts, noises, frame_count, configs, !args.has("no-fit"), fit_settings);
      return 0;
    }
    if (view_counts.empty()) view_counts = {4, 16};
    const std::vector<Variant>& variants = configs;

    std::vector<Scene> scenes;
    for (const int v : view_counts) scenes.push_back(render(placed, v, frame_count, 0.02f));
    std::map<std::pair<std::size_t, std::size_t>, std::vector<double>> rates, wall_rates;
    std::map<std::pair<std::size_t, std::size_t>, Pass> last;
    const bool with_fit = !args.has("no-fit");
    std::map<std::size_t, std::vector<double>> fit_rates;
    std::map<std::size_t, FitPass> fit_last;
    for (long pass = 0; pass < args.integer("repeats"); ++pass) {
      for (std::size_t s = 0; s < scenes.size(); ++s) {
        for (std::size_t v = 0; v < variants.size(); ++v) {
          const Pass p = run(scenes[s], variants[v], people, args.number("budget"));
          rates[{s, v}].push_back(p.frame_sets_per_s);
          wall_rates[{s, v}].push_back(p.frame_sets_per_wall_s);
          last[{s, v}] = p;
        }
        if (with_fit) {
          fit_last[s] = run_fit(scenes[s], variants[0], people, true, fit_settings);
          fit_rates[s].push_back(fit_last[s].frame_sets_per_s);
        }
      }
    }
    std::cout
        << "## Multi-view association + triangulation + tracking, one core\n\n"
        << people << " people, " << args.get("frames")
        << " frame sets at 30 fps, σ 2 %, 10 % joints dropped, 5 % outlier keypoints, "
           "false detections, occlusion; 1920x1080 cameras on a 6 m ring\n\n"
        << "| views | configuration | frame sets/s (CPU) | µs per frame set | frame sets/s "
           "(wall) | frames timed | MPJPE mm | wrong associations | id switches | coverage |\n"
        << "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (std::size_t s = 0; s < scenes.size(); ++s) {
      for (std::size_t v = 0; v < variants.size(); ++v) {
        const double rate = median(rates[{s, v}]);
        const Pass& p = last[{s, v}];
        std::cout << "| " << scenes[s].views << " | " << variants[v].name << " | " << std::fixed
                  << std::setprecision(0) << rate << " | " << 1e6 / rate << " | "
                  << median(wall_rates[{s, v}]) << " | " << p.frames << " | "
                  << std::setprecision(1) << p.score.mpjpe_mm() << " | "
                  << p.score.wrong_associations << " / " << p.score.person_frames << " | "
                  << p.score.id_switches << " | " << std::setprecision(3) << p.score.coverage()
                  << " |\n";
      }
      if (with_fit) {
        const double rate = median(fit_rates[s]);
        const FitPass& p = fit_last[s];
        std::cout << "| " << scenes[s].views
                  << " | live skeleton fit alone (lag 3, on ours' tracks; " << std::setprecision(1)
                  << p.mean_iterations << " iterations per solve) | " << std::setprecision(0)
                  << rate << " | " << 1e6 / rate << " | - | " << scenes[s].input.size() << " | "
                  << std::setprecision(1) << p.score.mpjpe_mm() << " | "
                  << p.score.wrong_associations << " / " << p.score.person_frames << " | "
                  << p.score.id_switches << " | " << std::setprecision(3) << p.score.coverage()
                  << " |\n";
      }
    }
    std::cout << "\nMedians over " << args.get("repeats")
              << " interleaved passes; single thread; rendering not timed; CPU: this thread's "
                 "CPU time (CLOCK_THREAD_CPUTIME_ID), wall: elapsed time. Targets (issue 19): "
                 "4 views x 6 people >= 1,000 frame sets/s, 16 views x 6 people >= 200/s; the live "
                 "skeleton fit >= 30 frame sets/s with 6 people (it runs on the whole scene in "
                 "every pass, without the budget).\n";
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-multiview: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
