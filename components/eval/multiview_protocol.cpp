#include "eval/multiview_protocol.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>

#include <glm/geometric.hpp>

#include "core/input_error.hpp"
#include "eval/procrustes.hpp"
#include "fit/track_fit.hpp"
#include "multiview/rig_reconstruction.hpp"
#include "posedb/builder.hpp"

namespace mocap::eval {
namespace {

double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

bool finite(const glm::vec3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

constexpr int kFirstFrame = 10;  // clip frames skipped at the start (CMU's inserted T-pose)

// Person i takes the i-th longest held-out clip (a property of the data, not of any result);
// places and yaws are spread so that people share the room without walking through each other.
std::vector<ScenePerson> place_people(const std::vector<TruthSequence>& clips, int count,
                                      int frames, std::uint64_t seed) {
  std::vector<const TruthSequence*> longest;
  for (const TruthSequence& c : clips) longest.push_back(&c);
  std::stable_sort(longest.begin(), longest.end(),
                   [](const auto* a, const auto* b) { return a->world.size() > b->world.size(); });
  std::vector<ScenePerson> people;
  for (int i = 0; i < count; ++i) {
    ScenePerson p;
    p.motion = longest[static_cast<std::size_t>(i) % longest.size()];
    p.first_frame = kFirstFrame + 400 * (i / static_cast<int>(longest.size()));
    people.push_back(p);
  }
  spread_people(people, frames, 2.5f, 0.5f, seed);
  return people;
}

// `views` cameras of a ring of max(views, 4): two or three are 90 degrees apart, as such rigs are
// set up (opposite cameras see depth along their axis poorly).
std::vector<camera::Camera> rig(int views) {
  auto cameras = ring_rig(std::max(views, 4), 6.0, 1.6, 0.9, {0.0, 1.0, 0.0}, Image{});
  cameras.resize(static_cast<std::size_t>(views));
  return cameras;
}

multiview::ReconstructionOptions options_of(MultiviewMethod method, double fps) {
  multiview::ReconstructionOptions o;
  o.tracker.fps = static_cast<float>(fps);
  if (method == MultiviewMethod::pose2sim_rule) {
    o.triangulation.method = multiview::TriangulationMethod::pose2sim;
    o.tracking = false;
  }
  if (method == MultiviewMethod::per_frame) o.tracking = false;
  return o;
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

}  // namespace

std::string_view method_label(MultiviewMethod method) {
  switch (method) {
    case MultiviewMethod::pose2sim_rule:
      return "(i) baseline: weighted DLT, Pose2Sim's exclusion rule";
    case MultiviewMethod::per_frame:
      return "(ii) ours per frame";
    case MultiviewMethod::tracking:
      return "(iii) ours + tracking";
    case MultiviewMethod::skeleton_fit:
      return "(iv) + skeleton fit, full";
    case MultiviewMethod::skeleton_fit_live:
      return "(iv) + skeleton fit, live";
    case MultiviewMethod::skeleton_fit_prior:
      return "(iv) + skeleton fit + monocular prior, full";
  }
  return "?";
}

bool fits_skeleton(MultiviewMethod method) {
  return method == MultiviewMethod::skeleton_fit || method == MultiviewMethod::skeleton_fit_live ||
         method == MultiviewMethod::skeleton_fit_prior;
}

std::vector<TruthSequence> load_heldout_clips(const std::string& cmu_folder, double fps) {
  const std::vector<std::string> files = posedb::split_files(cmu_folder, "heldout");
  if (files.empty()) throw InputError(cmu_folder + "/splits.txt", "no heldout clips listed");
  return load_truth(files, fps);
}

void add_track_metrics(const std::vector<ScenePersonTrack>& tracks, MultiviewResult& out) {
  double pa_sum = 0.0, accel_sum = 0.0, bone_std_sum = 0.0, truth_bone_std_sum = 0.0;
  long pa_joints = 0, accel_joints = 0, bones = 0;
  for (const ScenePersonTrack& t : tracks) {
    const std::size_t frames = std::min(t.truth.size(), t.reconstructed.size());
    for (std::size_t f = 0; f < frames; ++f) {
      if (!t.truth[f]) continue;
      std::vector<glm::dvec3> from, to;
      for (int j = 0; j < kBodyJoints; ++j) {
        if (!finite(t.reconstructed[f][j])) continue;
        from.emplace_back(t.reconstructed[f][j]);
        to.emplace_back((*t.truth[f])[j]);
      }
      if (from.size() < 4) continue;
      const Similarity s = procrustes(from, to);
      for (std::size_t k = 0; k < from.size(); ++k)
        pa_sum += glm::distance(s.apply(from[k]), to[k]);
      pa_joints += static_cast<long>(from.size());
    }
    for (std::size_t f = 1; f + 1 < frames; ++f) {
      if (!t.truth[f - 1] || !t.truth[f] || !t.truth[f + 1]) continue;
      for (int j = 0; j < kBodyJoints; ++j) {
        const glm::vec3 &a = t.reconstructed[f - 1][j], &b = t.reconstructed[f][j],
                        &c = t.reconstructed[f + 1][j];
        if (!finite(a) || !finite(b) || !finite(c)) continue;
        const glm::vec3 ours = a - 2.0f * b + c;
        const glm::vec3 truth =
            (*t.truth[f - 1])[j] - 2.0f * (*t.truth[f])[j] + (*t.truth[f + 1])[j];
        accel_sum += glm::distance(ours, truth);
        ++accel_joints;
      }
    }
    for (int j = 0; j < kBodyJoints; ++j) {
      const int parent = kJointParent[static_cast<std::size_t>(j)];
      if (parent < 0) continue;
      double sum = 0.0, square = 0.0, truth_sum = 0.0, truth_square = 0.0;
      long n = 0;
      for (std::size_t f = 0; f < frames; ++f) {
        const glm::vec3 &a = t.reconstructed[f][j], &b = t.reconstructed[f][parent];
        if (!finite(a) || !finite(b) || !t.truth[f]) continue;
        const double length = glm::distance(a, b);
        const double truth = glm::distance((*t.truth[f])[j], (*t.truth[f])[parent]);
        sum += length;
        square += length * length;
        truth_sum += truth;
        truth_square += truth * truth;
        ++n;
      }
      if (n < 2) continue;
      const double mean = sum / n, truth_mean = truth_sum / n;
      bone_std_sum += std::sqrt(std::max(0.0, square / n - mean * mean));
      truth_bone_std_sum += std::sqrt(std::max(0.0, truth_square / n - truth_mean * truth_mean));
      ++bones;
    }
  }
  out.pa_mpjpe_mm = pa_joints > 0 ? 1000.0 * pa_sum / pa_joints : NAN;
  out.accel_error_mm = accel_joints > 0 ? 1000.0 * accel_sum / accel_joints : NAN;
  out.bone_std_mm = bones > 0 ? 1000.0 * bone_std_sum / bones : NAN;
  out.truth_bone_std_mm = bones > 0 ? 1000.0 * truth_bone_std_sum / bones : NAN;
}

std::vector<MultiviewResult> run_multiview_case(const std::vector<TruthSequence>& clips,
                                                const MultiviewCase& scene,
                                                const MultiviewProtocolOptions& options) {
  if (clips.empty()) throw std::invalid_argument("run_multiview_case: no clips");
  const auto people = place_people(clips, scene.people, options.frames, options.seed);
  const auto cameras = rig(scene.views);
  std::vector<multiview::ViewGeometry> geometry;
  for (const camera::Camera& c : cameras) geometry.push_back(multiview::from_camera(c));
  SceneRenderer renderer(cameras, options.seed);
  SceneDegradation d;
  d.noise = scene.noise;
  d.dropout = options.dropout;
  d.outliers = options.outliers;
  d.false_detections = options.false_detections;
  d.occlusion = options.occlusion;
  std::vector<SceneFrame> frames;
  std::vector<multiview::FrameObservations> input;
  for (int f = 0; f < options.frames; ++f) {
    frames.push_back(renderer.render(people, f, d));
    SceneRenderer::to_observations(frames.back(), input.emplace_back());
  }

  // (iv) fits (iii)'s reconstruction: it is kept, with the CPU time it took. The fit's weights
  // are its defaults (chosen on train scenes, docs/fitting.md), the floor the scene's (y = 0).
  fit::MultiViewFitOptions fit_options;
  fit_options.cameras = cameras;
  fit_options.fit = fit::multiview_fit_defaults();
  fit_options.fit.ground = GroundPlane{{0.0, 1.0, 0.0}, 0.0};
  std::vector<multiview::FrameResult> tracked;
  double tracked_cpu_s = 0.0;
  std::vector<MultiviewResult> out;
  std::vector<MultiviewMethod> methods = {
      MultiviewMethod::pose2sim_rule, MultiviewMethod::per_frame, MultiviewMethod::tracking,
      MultiviewMethod::skeleton_fit, MultiviewMethod::skeleton_fit_live};
  if (options.prior_db) methods.push_back(MultiviewMethod::skeleton_fit_prior);
  for (const MultiviewMethod method : methods) {
    MultiviewResult r;
    r.scene = scene;
    r.method = method;
    SceneScorer scorer(scene.people, true);
    if (fits_skeleton(method)) {
      std::vector<multiview::FrameResult> results = tracked;
      const double start = thread_cpu_s();
      std::optional<fit::MonocularPrior> prior;
      if (method == MultiviewMethod::skeleton_fit_prior)
        prior.emplace(*options.prior_db, options.prior);
      fit::fit_tracks(std::span(input).first(results.size()), results, fit_options,
                      method == MultiviewMethod::skeleton_fit_live,
                      multiview::KeypointSet::body15(), prior ? &*prior : nullptr);
      r.cpu_s = tracked_cpu_s + thread_cpu_s() - start;
      r.frames = static_cast<long>(results.size());
      for (std::size_t f = 0; f < results.size(); ++f) scorer.add(frames[f], results[f]);
    } else {
      multiview::MultiViewReconstructor reconstructor(geometry, multiview::KeypointSet::body15(),
                                                      options_of(method, options.fps));
      for (std::size_t f = 0; f < input.size() && r.cpu_s < options.budget_s; ++f) {
        const double start = thread_cpu_s();
        const multiview::FrameResult& result =
            reconstructor.process(input[f], static_cast<std::int64_t>(f));
        r.cpu_s += thread_cpu_s() - start;
        scorer.add(frames[f], result);
        if (method == MultiviewMethod::tracking) tracked.push_back(result);
        ++r.frames;
      }
      if (method == MultiviewMethod::tracking) tracked_cpu_s = r.cpu_s;
    }
    r.score = scorer.score();
    add_track_metrics(scorer.tracks(), r);
    out.push_back(r);
  }
  return out;
}

std::string multiview_table(const std::vector<MultiviewResult>& results) {
  std::ostringstream s;
  s << "| views | people | σ | method | frames | MPJPE mm | PA-MPJPE mm | accel mm/frame² | bone "
       "std mm | wrong associations | id switches | coverage |\n"
    << "|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const MultiviewResult& r : results) {
    s << "| " << r.scene.views << " | " << r.scene.people << " | "
      << fixed(100.0 * r.scene.noise, 0) << " % | " << method_label(r.method) << " | ";
    const bool ids = r.method == MultiviewMethod::tracking || fits_skeleton(r.method);
    s << r.frames << " | " << fixed(r.score.mpjpe_mm(), 1) << " | " << fixed(r.pa_mpjpe_mm, 1)
      << " | " << fixed(r.accel_error_mm, 1) << " | " << fixed(r.bone_std_mm, 1) << " | "
      << r.score.wrong_associations << " / " << r.score.person_frames << " ("
      << fixed(100.0 * r.wrong_association_share(), 2) << " %) | "
      << (ids ? std::to_string(r.score.id_switches) : std::string("– (no ids)")) << " | "
      << fixed(r.score.coverage(), 3) << " |\n";
  }
  return s.str();
}

}  // namespace mocap::eval
