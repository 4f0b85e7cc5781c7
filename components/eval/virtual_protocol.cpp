#include "eval/virtual_protocol.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "eval/metrics.hpp"
#include "posedb/builder.hpp"

namespace mocap::eval {

std::string Condition::label() const {
  char buf[64];
  std::snprintf(buf, sizeof buf, "σ=%g%% drop=%g%%", noise * 100.0, dropout * 100.0);
  return buf;
}

std::vector<TruthSequence> load_truth(const std::vector<std::string>& files, double fps) {
  // The database builder already reads, maps, resamples and faces every frame; undo the facing.
  posedb::BuildOptions options;
  options.fps = fps;
  options.views.yaw_steps = 1;
  options.views.heights_m = {1.5f};
  options.clusters = 1;
  posedb::BuildReport report;
  const posedb::DatabaseContents db = posedb::build_database(files, options, {}, report);
  std::vector<TruthSequence> out;
  for (const auto& clip : db.clips) {
    TruthSequence s;
    s.clip = clip.name;
    for (std::uint32_t f = clip.first_frame; f < clip.first_frame + clip.frame_count; ++f) {
      const auto& r = db.frames[f];
      const glm::quat facing = glm::angleAxis(r.heading_rad, glm::vec3(0, 1, 0));
      const glm::vec3 root(r.root_m[0], r.root_m[1], r.root_m[2]);
      Body body;
      for (int j = 0; j < kBodyJoints; ++j) {
        const float* p = &db.joints[(static_cast<std::size_t>(f) * kBodyJoints + j) * 3];
        body[j] = facing * glm::vec3(p[0], p[1], p[2]) + root;
      }
      s.world.push_back(body);
    }
    out.push_back(std::move(s));
  }
  return out;
}

namespace {

// World (y up) to camera (x right, y down, z forward) for a camera at `yaw` around the person,
// looking horizontally towards them and then tilted by `pitch`.
glm::quat camera_rotation(const VirtualCamera& c) {
  const float yaw = glm::radians(c.yaw_deg), pitch = glm::radians(c.pitch_deg);
  const glm::vec3 towards(-std::sin(yaw), 0.0f, -std::cos(yaw));  // horizontal view direction
  const glm::vec3 forward =
      glm::normalize(towards * std::cos(pitch) + glm::vec3(0, std::sin(pitch), 0));
  const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0, 1, 0)));
  const glm::vec3 down = glm::cross(forward, right);
  glm::mat3 m;
  for (int i = 0; i < 3; ++i) m[i] = glm::vec3(right[i], down[i], forward[i]);
  return glm::quat_cast(m);
}

}  // namespace

void InputNoise::apply(const Condition& condition, recon::BodyXyc& body) {
  float top = std::numeric_limits<float>::max(), bottom = -top;
  for (int j = 0; j < kBodyJoints; ++j) {
    top = std::min(top, body[3 * j + 1]);
    bottom = std::max(bottom, body[3 * j + 1]);
  }
  const float sigma = condition.noise * (bottom - top);
  for (int j = 0; j < kBodyJoints; ++j) {
    body[3 * j] += sigma * gauss_(rng_);
    body[3 * j + 1] += sigma * gauss_(rng_);
    if (j != index(Joint::root) && uniform_(rng_) < condition.dropout) body[3 * j + 2] = 0.0f;
  }
}

RenderedSequence render(const TruthSequence& seq, const VirtualCamera& cam, const Image& image,
                        const Condition& cond, std::uint64_t seed,
                        const recon::LayoutOffsets* input_layout) {
  RenderedSequence out;
  InputNoise noise(seed);
  const glm::quat rotation = camera_rotation(cam);
  const float focal = 0.5f * static_cast<float>(image.width) /
                      std::tan(glm::radians(image.horizontal_fov_deg) / 2.0f);
  const float yaw = glm::radians(cam.yaw_deg);
  for (const Body& world : seq.world) {
    const glm::vec3 root = world[index(Joint::root)];
    const glm::vec3 position(root.x + cam.distance_m * std::sin(yaw), cam.height_m,
                             root.z + cam.distance_m * std::cos(yaw));
    Body camera_frame;
    recon::BodyXyc xyc;
    for (int j = 0; j < kBodyJoints; ++j) camera_frame[j] = rotation * (world[j] - position);
    Body keypoints = camera_frame;
    if (input_layout) recon::apply_layout_offsets_3d(*input_layout, keypoints, -1.0f);
    for (int j = 0; j < kBodyJoints; ++j) {
      const glm::vec3& p = keypoints[j];
      xyc[3 * j] = focal * p.x / p.z + 0.5f * static_cast<float>(image.width);
      xyc[3 * j + 1] = focal * p.y / p.z + 0.5f * static_cast<float>(image.height);
      xyc[3 * j + 2] = p.z > 0.1f ? 1.0f : 0.0f;
    }
    noise.apply(cond, xyc);
    out.input.push_back(xyc);
    out.truth_camera.push_back(camera_frame);
  }
  return out;
}

void Scores::add(const Scores& o) {
  frames += o.frames;
  valid += o.valid;
  mpjpe_sum += o.mpjpe_sum;
  pa_mpjpe_sum += o.pa_mpjpe_sum;
  accel_sum += o.accel_sum;
  accel_frames += o.accel_frames;
  jitter_sum += o.jitter_sum;
}

Scores score(const std::vector<recon::Pose3D>& prediction, const std::vector<Body>& truth) {
  Scores s;
  s.frames = static_cast<double>(truth.size());
  std::size_t t = 0;
  while (t < prediction.size()) {
    if (!prediction[t].valid) {
      ++t;
      continue;
    }
    std::size_t end = t;
    while (end < prediction.size() && prediction[end].valid) ++end;
    std::vector<PoseView> pred, real;
    for (std::size_t i = t; i < end; ++i) {
      pred.emplace_back(prediction[i].joints);
      real.emplace_back(truth[i]);
      s.mpjpe_sum += mpjpe(pred.back(), real.back()).mean_mm;
      s.pa_mpjpe_sum += pa_mpjpe(pred.back(), real.back()).mean_mm;
      s.valid += 1;
    }
    if (end - t >= 3) {
      const ErrorAccumulator accel = acceleration_errors(pred, real);
      const ErrorAccumulator jit = jitter(pred);
      s.accel_sum += accel.mean_mm() * static_cast<double>(accel.frames());
      s.jitter_sum += jit.mean_mm() * static_cast<double>(jit.frames());
      s.accel_frames += static_cast<double>(accel.frames());
    }
    t = end;
  }
  return s;
}

std::vector<VirtualCamera> default_cameras(bool quick) {
  struct Family {
    const char* name;
    float height, pitch;
  };
  const Family families[] = {{"low 1.0 m, 0°", 1.0f, 0.0f},
                             {"level 1.5 m, 0°", 1.5f, 0.0f},
                             {"high 2.5 m, -15°", 2.5f, -15.0f},
                             {"steep 2.5 m, -35°", 2.5f, -35.0f}};
  std::vector<float> yaws = {0.0f, 45.0f, 90.0f, 135.0f, 180.0f};
  if (quick) yaws = {0.0f, 90.0f};
  std::vector<VirtualCamera> cameras;
  for (const auto& f : families) {
    for (float y : yaws) cameras.push_back({f.name, y, f.height, f.pitch, 4.5f});
  }
  return cameras;
}

std::vector<Condition> default_conditions(bool quick) {
  if (quick) return {{0.0f, 0.0f}, {0.02f, 0.0f}};
  return {{0.0f, 0.0f}, {0.01f, 0.0f}, {0.02f, 0.0f}, {0.05f, 0.0f}, {0.02f, 0.1f}};
}

}  // namespace mocap::eval
