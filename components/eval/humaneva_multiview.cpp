#include "eval/humaneva_multiview.hpp"

#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "core/input_error.hpp"
#include "fit/scene_fit.hpp"
#include "multiview/rig_reconstruction.hpp"

namespace mocap::eval {

namespace he = io::humaneva;

std::vector<HumanEvaTake> humaneva_takes(const std::vector<HumanEvaSequence>& sequences,
                                         const HumanEvaCameras& cameras) {
  if (sequences.size() % he::kCameras != 0)
    throw std::invalid_argument("humaneva_takes: not three cameras per chunk");
  std::vector<HumanEvaTake> out;
  for (std::size_t first = 0; first < sequences.size(); first += he::kCameras) {
    HumanEvaTake take;
    const HumanEvaSequence& c1 = sequences[first];
    for (std::size_t c = 0; c < he::kCameras; ++c) {
      const HumanEvaSequence& s = sequences[first + c];
      if (s.subject != c1.subject || s.chunk != c1.chunk || s.input.size() != c1.input.size() ||
          s.camera.name != he::kCameraNames[c])
        throw std::invalid_argument("humaneva_takes: " + c1.subject + " " + c1.chunk +
                                    " does not have C1, C2, C3 in order");
      take.sequence[c] = first + c;
    }
    const camera::Rig& rig = cameras.at(c1.subject);
    if (!rig.floor)
      throw InputError(std::string(he::kCamerasFile), c1.subject + "'s rig has no floor");
    take.floor = *rig.floor;
    for (const Body& in_camera : c1.truth_camera) {
      Body world;
      for (int j = 0; j < kBodyJoints; ++j)
        world[j] = glm::vec3(c1.camera.to_world(glm::dvec3(in_camera[j])));
      take.truth_world.push_back(world);
    }
    out.push_back(std::move(take));
  }
  return out;
}

std::string cameras_label(std::span<const int> cameras) {
  std::string label;
  for (const int c : cameras) {
    if (!label.empty()) label += "+";
    label += std::string(he::kCameraNames.at(static_cast<std::size_t>(c)));
  }
  return label;
}

namespace {

// The person seen in the most views of each frame as a pose (valid with all 15 joints).
std::vector<recon::Pose3D> subject_poses(const std::vector<multiview::FrameResult>& results,
                                         long* extra_people, long* partial_frames) {
  std::vector<recon::Pose3D> poses(results.size());
  for (std::size_t f = 0; f < results.size(); ++f) {
    const multiview::FrameResult& result = results[f];
    if (result.people.empty()) continue;
    std::size_t best = 0;
    for (std::size_t p = 1; p < result.people.size(); ++p)
      if (std::popcount(result.people[p].views) > std::popcount(result.people[best].views))
        best = p;
    if (extra_people) *extra_people += static_cast<long>(result.people.size() - 1);
    const auto body = result.body_of(best);
    recon::Pose3D& pose = poses[f];
    pose.valid = true;
    for (int j = 0; j < kBodyJoints; ++j) {
      pose.joints[j] = body[j].position;
      const glm::vec3& p = pose.joints[j];
      if (!body[j].valid() || !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        pose.valid = false;
    }
    if (!pose.valid && partial_frames) ++*partial_frames;
  }
  return poses;
}

}  // namespace

TakeReconstruction reconstruct_take(const HumanEvaTake& take,
                                    const std::vector<HumanEvaSequence>& sequences,
                                    std::span<const std::vector<recon::BodyXyc>> inputs,
                                    std::span<const int> cameras,
                                    const HumanEvaMultiviewOptions& options) {
  if (inputs.size() != he::kCameras || cameras.empty())
    throw std::invalid_argument("reconstruct_take: three inputs and at least one camera");
  std::vector<multiview::ViewGeometry> geometry;
  std::vector<camera::Camera> rig;
  for (const int c : cameras) {
    rig.push_back(sequences.at(take.sequence.at(static_cast<std::size_t>(c))).camera);
    geometry.push_back(multiview::from_camera(rig.back()));
  }
  multiview::ReconstructionOptions reconstruction = options.reconstruction;
  reconstruction.tracker.fps = static_cast<float>(options.fps);
  multiview::MultiViewReconstructor reconstructor(geometry, multiview::KeypointSet::body15(),
                                                  reconstruction);
  const std::size_t frames = take.truth_world.size();
  const int views = static_cast<int>(cameras.size());
  std::vector<multiview::FrameObservations> observations(frames);
  std::vector<multiview::FrameResult> results;
  results.reserve(frames);
  for (std::size_t f = 0; f < frames; ++f) {
    observations[f].reset(views, kBodyJoints);
    for (int v = 0; v < views; ++v) {
      const recon::BodyXyc& in = inputs[static_cast<std::size_t>(cameras[v])].at(f);
      const std::span<float> xyc = observations[f].add_person(v);
      for (int j = 0; j < kBodyJoints; ++j) {
        if (!(in[3 * j + 2] > 0.0f)) continue;  // missing: stays (NaN, NaN, 0)
        const glm::dvec2 pixel =
            rig[static_cast<std::size_t>(v)].undistort_pixel({in[3 * j], in[3 * j + 1]});
        xyc[3 * j] = static_cast<float>(pixel.x);
        xyc[3 * j + 1] = static_cast<float>(pixel.y);
        xyc[3 * j + 2] = in[3 * j + 2];
      }
    }
    results.push_back(reconstructor.process(observations[f], static_cast<std::int64_t>(f)));
  }
  TakeReconstruction out;
  out.triangulated = subject_poses(results, &out.extra_people, &out.partial_frames);
  if (options.fit) {
    fit::MultiViewFitOptions fit_options;
    fit_options.cameras = rig;
    fit_options.fit = fit::multiview_fit_defaults();
    fit_options.fit.ground = take.floor;
    std::vector<multiview::FrameResult> triangulated;
    if (options.prior_db) triangulated = results;  // the prior's fit starts from these too
    fit::fit_tracks(observations, results, fit_options, /*live=*/false);
    out.fitted = subject_poses(results, nullptr, nullptr);
    if (options.prior_db) {
      fit::MonocularPrior prior(*options.prior_db, options.prior);
      fit::fit_tracks(observations, triangulated, fit_options, /*live=*/false,
                      multiview::KeypointSet::body15(), &prior);
      out.fitted_prior = subject_poses(triangulated, nullptr, nullptr);
    }
  }
  return out;
}

void TakeScores::add(const TakeScores& other) {
  pose.add(other.pose);
  absolute_m += other.absolute_m;
  absolute_frames += other.absolute_frames;
  tracks.insert(tracks.end(), other.tracks.begin(), other.tracks.end());
}

TakeScores score_take(const std::vector<recon::Pose3D>& poses, const std::vector<Body>& truth,
                      const std::vector<char>* keep, bool absolute) {
  if (poses.size() != truth.size() || (keep && keep->size() != truth.size()))
    throw std::invalid_argument("score_take: poses, truth and keep differ in length");
  std::vector<recon::Pose3D> kept = poses;
  if (keep)
    for (std::size_t f = 0; f < kept.size(); ++f)
      if (!(*keep)[f]) kept[f].valid = false;
  TakeScores out;
  out.pose = score(kept, truth);
  Body missing;
  missing.fill(glm::vec3(std::numeric_limits<float>::quiet_NaN()));
  ScenePersonTrack& track = out.tracks.emplace_back();
  for (std::size_t f = 0; f < kept.size(); ++f) {
    track.truth.emplace_back(truth[f]);
    track.reconstructed.push_back(kept[f].valid ? kept[f].joints : missing);
    if (!absolute || !kept[f].valid) continue;
    double sum = 0.0;
    for (int j = 0; j < kBodyJoints; ++j) sum += glm::distance(kept[f].joints[j], truth[f][j]);
    out.absolute_m += sum / kBodyJoints;
    ++out.absolute_frames;
  }
  return out;
}

}  // namespace mocap::eval
