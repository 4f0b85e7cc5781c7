#pragma once
// A held-out CMU clip (07_01, walking) seen by one of the virtual protocol's cameras, loaded once
// per test program, and the fitter's inputs built from it.

#include <cmath>
#include <random>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "eval/virtual_protocol.hpp"
#include "fit/fit_evaluation.hpp"
#include "fit/skeleton_fit.hpp"
#include "support/shared_data.hpp"

namespace mocap::test {

inline constexpr const char* kFitClip = "mocap/cmu31/07_01.bvh";
inline constexpr double kFitFps = 24.0;

// The clip's world joints (empty when the shared data is absent).
inline const std::vector<eval::Body>& fit_clip_world() {
  static const std::vector<eval::Body> world = [] {
    const auto file = shared_data() / kFitClip;
    if (!std::filesystem::exists(file)) return std::vector<eval::Body>{};
    return eval::load_truth({file.string()}, kFitFps).front().world;
  }();
  return world;
}

#define MOCAP_REQUIRE_FIT_CLIP() MOCAP_REQUIRE_SHARED(::mocap::test::kFitClip)

// The protocol's camera (the fit's and the retrieval's), at the world origin.
inline camera::Camera fit_camera() {
  const eval::Image image;
  return camera::Camera::from_fov(image.width, image.height, image.horizontal_fov_deg);
}
inline camera::Camera fit_lens() { return fit_camera(); }

struct FitScene {
  std::vector<eval::Body> world;
  eval::RenderedSequence rendered;
  std::vector<camera::Camera> cameras;  // each frame's (the camera follows the person)
};

// Frames [first, first + count) of the clip through a camera at `yaw_deg`, 1.5 m high, 4.5 m
// away, with 2D noise (fraction of the 2D height) and no drop-out.
inline FitScene fit_scene(std::size_t first, std::size_t count, float yaw_deg, float noise,
                          std::uint64_t seed = 7) {
  FitScene s;
  const auto& all = fit_clip_world();
  s.world.assign(all.begin() + static_cast<std::ptrdiff_t>(first),
                 all.begin() + static_cast<std::ptrdiff_t>(std::min(all.size(), first + count)));
  const eval::TruthSequence truth{"07_01", s.world};
  s.rendered = eval::render(truth, {"level", yaw_deg, 1.5f, 0.0f, 4.5f}, {}, {noise, 0.0f}, seed);
  s.cameras = fit::moving_cameras(fit_camera(), s.world, s.rendered.truth_camera);
  return s;
}

inline eval::Body root_relative(const eval::Body& b) {
  eval::Body out = b;
  for (auto& p : out) p -= b[index(Joint::root)];
  return out;
}

// The truth's root-relative poses with every bone turned by `angle_rad` about a random axis, or
// with `in_image` about the camera's optical axis (a change the 2D shows in full).
inline std::vector<recon::Pose3D> perturbed_truth(const std::vector<eval::Body>& camera,
                                                  float angle_rad, std::uint64_t seed,
                                                  bool in_image = false) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> gauss;
  std::vector<recon::Pose3D> out(camera.size());
  for (std::size_t t = 0; t < camera.size(); ++t) {
    const eval::Body rel = root_relative(camera[t]);
    out[t].valid = true;
    out[t].joints[index(Joint::root)] = glm::vec3(0.0f);
    // Turn each bone's vector; children follow their parent's new end.
    std::array<glm::vec3, kBodyJoints> bone{};
    for (int j = 0; j < kBodyJoints; ++j) {
      if (kJointParent[j] < 0) continue;
      const glm::vec3 axis = glm::normalize(glm::vec3(gauss(rng), gauss(rng), gauss(rng)));
      const float sign = gauss(rng) < 0.0f ? -1.0f : 1.0f;
      bone[j] = (in_image ? glm::angleAxis(sign * angle_rad, glm::vec3(0, 0, 1))
                          : glm::angleAxis(angle_rad, axis)) *
                (rel[j] - rel[kJointParent[j]]);
    }
    for (int j = 0; j < kBodyJoints; ++j) {
      if (kJointParent[j] < 0) continue;
      glm::vec3 p(0.0f);
      for (int k = j; kJointParent[k] >= 0; k = kJointParent[k]) p += bone[k];
      out[t].joints[j] = p;
    }
  }
  return out;
}

inline double mean_mpjpe_mm(const std::vector<fit::FittedFrame>& fitted,
                            const std::vector<eval::Body>& truth_camera) {
  double sum = 0;
  int n = 0;
  for (std::size_t t = 0; t < fitted.size(); ++t) {
    if (!fitted[t].valid) continue;
    const eval::Body a = fitted[t].root_relative(), b = root_relative(truth_camera[t]);
    for (int j = 0; j < kBodyJoints; ++j) sum += glm::distance(a[j], b[j]), ++n;
  }
  return n ? 1000.0 * sum / n : 1e9;
}

inline double mean_mpjpe_mm(const std::vector<recon::Pose3D>& poses,
                            const std::vector<eval::Body>& truth_camera) {
  double sum = 0;
  int n = 0;
  for (std::size_t t = 0; t < poses.size(); ++t) {
    if (!poses[t].valid) continue;
    const eval::Body b = root_relative(truth_camera[t]);
    for (int j = 0; j < kBodyJoints; ++j) sum += glm::distance(poses[t].joints[j], b[j]), ++n;
  }
  return n ? 1000.0 * sum / n : 1e9;
}

}  // namespace mocap::test
