#include "fit/fit_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "eval/procrustes.hpp"

namespace mocap::fit {

std::vector<camera::Camera> moving_cameras(const camera::Camera& lens,
                                           std::span<const eval::Body> world,
                                           std::span<const eval::Body> camera) {
  std::vector<camera::Camera> out(std::min(world.size(), camera.size()), lens);
  for (std::size_t t = 0; t < out.size(); ++t) {
    std::array<glm::dvec3, kBodyJoints> from, to;
    for (int j = 0; j < kBodyJoints; ++j) from[j] = camera[t][j], to[j] = world[t][j];
    const eval::Similarity s = eval::procrustes(from, to, eval::Alignment::rigid);
    out[t].set_pose_from_centre(s.rotation, s.translation);
  }
  return out;
}

std::vector<FrameInput> make_inputs(std::span<const recon::BodyXyc> keypoints,
                                    std::span<const recon::Pose3D> retrieved,
                                    std::span<const std::array<bool, 2>> contacts,
                                    std::span<const camera::Camera> cameras) {
  std::vector<FrameInput> out(keypoints.size());
  for (std::size_t t = 0; t < out.size(); ++t) {
    out[t].keypoints = keypoints[t];
    if (t < retrieved.size() && retrieved[t].valid) {
      out[t].retrieved_valid = true;
      out[t].retrieved = retrieved[t].joints;
    }
    if (t < contacts.size()) out[t].contact = contacts[t];
    if (t < cameras.size()) out[t].moving_camera = cameras[t];
  }
  return out;
}

double ankle_floor(std::span<const eval::Body> world) {
  double floor = std::numeric_limits<double>::max();
  for (const auto& b : world)
    for (int a : kFeet) floor = std::min<double>(floor, b[a].y);
  return floor;
}

std::vector<std::array<bool, 2>> truth_contacts(std::span<const eval::Body> world, double fps,
                                                const ContactOptions& options) {
  std::vector<std::array<bool, 2>> out(world.size());
  if (world.size() < 2) return out;
  const double floor = ankle_floor(world);
  for (std::size_t t = 0; t < world.size(); ++t) {
    const std::size_t other = t + 1 < world.size() ? t + 1 : t - 1;
    for (int s = 0; s < 2; ++s) {
      const double speed = glm::distance(world[t][kFeet[s]], world[other][kFeet[s]]) * fps;
      out[t][s] =
          speed < options.max_speed_mps && world[t][kFeet[s]].y - floor < options.max_height_m;
    }
  }
  return out;
}

void PlacementScores::add(const PlacementScores& o) {
  frames += o.frames;
  root_error_m += o.root_error_m;
  skate_m += o.skate_m;
  skate_steps += o.skate_steps;
  below_floor_m += o.below_floor_m;
  below_floor_count += o.below_floor_count;
  ankle_frames += o.ankle_frames;
}

PlacementScores score_placement(std::span<const FittedFrame> fitted,
                                std::span<const eval::Body> truth_camera,
                                std::span<const camera::Camera> cameras,
                                std::span<const std::array<bool, 2>> contacts, double floor_y) {
  PlacementScores s;
  const std::size_t n = std::min({fitted.size(), truth_camera.size(), cameras.size()});
  auto world = [&](std::size_t t, int joint) {
    return cameras[t].to_world(glm::dvec3(fitted[t].joints[joint]));
  };
  for (std::size_t t = 0; t < n; ++t) {
    if (!fitted[t].valid) continue;
    s.frames += 1;
    s.root_error_m += glm::distance(glm::dvec3(fitted[t].root()),
                                    glm::dvec3(truth_camera[t][index(Joint::root)]));
    for (int side = 0; side < 2; ++side) {
      const glm::dvec3 p = world(t, kFeet[side]);
      s.ankle_frames += 1;
      const double below = floor_y - p.y;
      s.below_floor_m += std::max(0.0, below);
      if (below > 0.01) s.below_floor_count += 1;
      if (t + 1 < n && fitted[t + 1].valid && t + 1 < contacts.size() && contacts[t][side] &&
          contacts[t + 1][side]) {
        const glm::dvec3 q = world(t + 1, kFeet[side]);
        s.skate_m += std::hypot(q.x - p.x, q.z - p.z);
        s.skate_steps += 1;
      }
    }
  }
  return s;
}

std::vector<recon::Pose3D> as_poses(std::span<const FittedFrame> fitted) {
  std::vector<recon::Pose3D> out(fitted.size());
  for (std::size_t t = 0; t < fitted.size(); ++t) {
    out[t].valid = fitted[t].valid;
    if (fitted[t].valid) out[t].joints = fitted[t].root_relative();
  }
  return out;
}

}  // namespace mocap::fit
