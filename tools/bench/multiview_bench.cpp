// `mocap-bench-multiview`: speed of association + triangulation + tracking (components/multiview)
// on one core, in frame sets per second (one frame set = every view's detections of one instant),
// for 4 and 16 views with 6 people, ours beside Pose2Sim's triangulation rule in the same pipeline
// and ours without tracking. The input is a virtual scene (eval/multiview_scene.hpp) of CMU *train*
// clips, rendered beforehand at the target condition (σ 2 % of the box height, 10 %
// joints dropped, 5 % outlier keypoints, false detections, occlusion); only process() is timed.
// Variants run interleaved; medians over the passes are reported, with the quality of the last
// pass beside (the speed of a wrong answer is no use).

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

Scene render(const std::vector<eval::ScenePerson>& people, int views, int frames) {
  Scene s;
  s.views = views;
  const auto rig = eval::ring_rig(views, 6.0, 1.6, 0.9, {0.0, 1.0, 0.0}, eval::Image{});
  for (const auto& c : rig) s.geometry.push_back(c.geometry());
  eval::SceneRenderer renderer(rig, 1);
  eval::SceneDegradation d;
  d.noise = 0.02f;
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

}  // namespace

int main(int argc, char** argv) {
  cli::Args args("mocap-bench-multiview [options]",
                 "Frame sets per second of association + triangulation + tracking on one core.");
  args.option("mocap", "DIR", "cmu31 folder with splits.txt", "../shared/data/mocap/cmu31")
      .option("people", "N", "people in the scene", "6")
      .option("views", "N", "camera counts to run (repeat the option)", std::nullopt, true)
      .option("frames", "N", "frame sets per scene (30 fps)", "300")
      .option("repeats", "N", "interleaved passes; medians are reported", "5")
      .option("budget", "S", "CPU seconds at most per pass and variant", "3");
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  try {
    const auto clips = load_clips(args.get("mocap"));
    const int people = static_cast<int>(args.integer("people"));
    const auto placed = place_people(clips, people, static_cast<int>(args.integer("frames")));
    std::vector<int> view_counts;
    for (const std::string& v : args.all("views")) view_counts.push_back(std::stoi(v));
    if (view_counts.empty()) view_counts = {4, 16};

    std::vector<Variant> variants(3);
    variants[0].name = "ours (association + robust triangulation + tracking)";
    variants[1].name = "ours without tracking (cold association every frame)";
    variants[1].options.tracking = false;
    variants[2].name = "baseline: Pose2Sim's rule (+ our association and tracking)";
    variants[2].options.triangulation.method = multiview::TriangulationMethod::pose2sim;

    std::vector<Scene> scenes;
    for (const int v : view_counts) {
      scenes.push_back(render(placed, v, static_cast<int>(args.integer("frames"))));
    }
    std::map<std::pair<std::size_t, std::size_t>, std::vector<double>> rates, wall_rates;
    std::map<std::pair<std::size_t, std::size_t>, Pass> last;
    for (long pass = 0; pass < args.integer("repeats"); ++pass) {
      for (std::size_t s = 0; s < scenes.size(); ++s) {
        for (std::size_t v = 0; v < variants.size(); ++v) {
          const Pass p = run(scenes[s], variants[v], people, args.number("budget"));
          rates[{s, v}].push_back(p.frame_sets_per_s);
          wall_rates[{s, v}].push_back(p.frame_sets_per_wall_s);
          last[{s, v}] = p;
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
    }
    std::cout << "\nMedians over " << args.get("repeats")
              << " interleaved passes; single thread; rendering not timed; CPU: this thread's "
                 "CPU time (CLOCK_THREAD_CPUTIME_ID), wall: elapsed time. Targets (issue 19): "
                 "4 views x 6 people >= 1,000 frame sets/s, 16 views x 6 people >= 200/s.\n";
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-multiview: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
