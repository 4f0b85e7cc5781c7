#include "eval/humaneva_protocol.hpp"

#include <cmath>
#include <span>

#include "core/input_error.hpp"
#include "core/keypoint_layout.hpp"
#include "eval/metrics.hpp"
#include "motion/pose_sequence.hpp"

namespace mocap::eval {

namespace he = io::humaneva;

glm::mat3 humaneva_world_to_y_up() {
  // Columns: where X, Y and Z go.
  return glm::mat3(glm::vec3(1, 0, 0), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0));
}

std::vector<std::string> humaneva_joint_correspondence() {
  const KeypointLayout& layout = mocap::layout(LayoutId::humaneva15);
  std::vector<std::string> lines;
  for (int j = 0; j < kBodyJoints; ++j) {
    const JointSource& source = layout.body[j];
    std::string line =
        std::string(kJointNames[j]) + " = HumanEva " + std::string(layout.keypoints[source.first]);
    if (source.second >= 0)
      line = std::string(kJointNames[j]) + " = midpoint of HumanEva " +
             std::string(layout.keypoints[source.first]) + " and " +
             std::string(layout.keypoints[source.second]);
    if (!source.how.empty()) line += " (" + std::string(source.how) + ")";
    lines.push_back(line);
  }
  return lines;
}

std::vector<posedb::BodySequence> humaneva_body_sequences(
    const he::Dataset& dataset, he::Split split, const std::vector<std::string_view>& actions) {
  const glm::mat3 to_y_up = humaneva_world_to_y_up();
  std::vector<posedb::BodySequence> out;
  for (const std::string_view action : actions) {
    for (const he::Chunk* chunk : dataset.select(split, "", action)) {
      posedb::BodySequence sequence;
      sequence.name = std::string(he::to_string(split)) + "/" + chunk->subject + " " + chunk->key;
      sequence.source = "HumanEva-I " + std::string(he::kPositions3dFile);
      sequence.family = "humaneva";
      sequence.mapping =
          "HumanEva-15: root = pelvis (torsoDistal), neck = thorax, head = headDistal; "
          "Z-up world turned to y up";
      sequence.fps = he::kFps;
      for (const he::Pose3& pose : chunk->positions_3d) {
        auto body = he::to_body15(pose);
        for (glm::vec3& p : body) p = to_y_up * p;
        sequence.frames.push_back(body);
      }
      out.push_back(std::move(sequence));
    }
  }
  return out;
}

namespace {

// The ground-truth 2D of one camera, resampled, as Body15 (x, y, confidence 1).
std::vector<recon::BodyXyc> input_2d(const std::vector<he::Pose2>& positions, double fps) {
  const KeypointLayout& layout = mocap::layout(LayoutId::humaneva15);
  std::vector<recon::BodyXyc> out;
  for (const he::Pose2& frame :
       motion::resample_points(std::span<const he::Pose2>(positions), he::kFps, fps)) {
    std::array<float, he::kJoints * 3> keypoints;
    for (int k = 0; k < he::kJoints; ++k) {
      keypoints[3 * k] = frame[k].x;
      keypoints[3 * k + 1] = frame[k].y;
      keypoints[3 * k + 2] = 1.0f;
    }
    recon::BodyXyc body;
    mocap::to_body15(layout, keypoints, body);
    out.push_back(body);
  }
  return out;
}

// The 3D truth, resampled, as Body15 in the camera's frame.
std::vector<Body> truth_in_camera(const std::vector<he::Pose3>& positions,
                                  const camera::Camera& camera, double fps) {
  std::vector<Body> out;
  for (const he::Pose3& frame :
       motion::resample_points(std::span<const he::Pose3>(positions), he::kFps, fps)) {
    Body body = he::to_body15(frame);
    for (glm::vec3& p : body) p = glm::vec3(camera.to_camera(glm::dvec3(p)));
    out.push_back(body);
  }
  return out;
}

}  // namespace

std::vector<HumanEvaSequence> humaneva_validation_sequences(const he::Dataset& dataset,
                                                            const HumanEvaCameras& cameras,
                                                            double fps, he::Split split) {
  std::vector<HumanEvaSequence> out;
  for (const std::string_view subject : kHumanEvaSubjects) {
    const auto subject_cameras = cameras.find(std::string(subject));
    if (subject_cameras == cameras.end())
      throw InputError(std::string(he::kCamerasFile), "no cameras for " + std::string(subject));
    for (const HumanEvaAction& action : kHumanEvaActions) {
      for (const he::Chunk* chunk : dataset.select(split, subject, action.data_name)) {
        for (int c = 0; c < he::kCameras; ++c) {
          if (chunk->positions_2d[c].size() != chunk->frames())
            throw InputError(std::string(he::kPositions2dFile),
                             "no 2D for " + chunk->subject + " " + chunk->key);
          const camera::Camera& camera = subject_cameras->second.cameras.at(c);
          out.push_back({chunk->subject, std::string(action.label), chunk->key, camera,
                         input_2d(chunk->positions_2d[c], fps),
                         truth_in_camera(chunk->positions_3d, camera, fps)});
        }
      }
    }
  }
  return out;
}

std::vector<recon::BodyXyc> noisy_input(const HumanEvaSequence& sequence,
                                        const Condition& condition, std::uint64_t seed) {
  std::vector<recon::BodyXyc> input = sequence.input;
  InputNoise noise(seed);
  for (recon::BodyXyc& frame : input) noise.apply(condition, frame);
  return input;
}

Scores evaluate_sequence(recon::Matcher& matcher, const recon::FrameBones& bones,
                         const HumanEvaSequence& sequence, const Condition& condition,
                         const recon::SequenceOptions& options, std::uint64_t seed,
                         const recon::LayoutOffsets* map_back, Scores* mapped) {
  auto poses =
      recon::reconstruct_sequence(matcher, bones, noisy_input(sequence, condition, seed), options);
  const Scores canonical = score(poses, sequence.truth_camera);
  if (map_back && mapped) {
    for (recon::Pose3D& pose : poses)
      if (pose.valid) recon::apply_layout_offsets_3d(*map_back, pose.joints, -1.0f);
    *mapped = score(poses, sequence.truth_camera);
  }
  return canonical;
}

void HumanEvaTable::add(const HumanEvaSequence& sequence, const Scores& scores) {
  cells_[{sequence.subject, sequence.action}].add(scores);
}

Scores HumanEvaTable::cell(std::string_view subject, std::string_view action) const {
  const auto found = cells_.find({std::string(subject), std::string(action)});
  return found == cells_.end() ? Scores{} : found->second;
}

Scores HumanEvaTable::all() const {
  Scores sum;
  for (const auto& [key, scores] : cells_) sum.add(scores);
  return sum;
}

double HumanEvaTable::mean_cell_pa_mpjpe() const {
  MeanAccumulator mean;
  for (const auto& [key, scores] : cells_) mean.add(scores.pa_mpjpe());
  return mean.mean();
}

}  // namespace mocap::eval
