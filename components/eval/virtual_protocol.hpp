#pragma once
// The paper's virtual-video protocol (§5.2), extended (../shared/docs/EVALUATION.md): held-out
// mocap seen by virtual cameras at several yaws, heights and pitches, 2D noise and joint
// drop-out added, reconstructed, and compared with the truth.

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/body15.hpp"
#include "recon/sequence_reconstruction.hpp"

namespace mocap::eval {

using Body = std::array<glm::vec3, kBodyJoints>;

// A held-out clip: world joints (metres, y up) per frame at the evaluation rate.
struct TruthSequence {
  std::string clip;
  std::vector<Body> world;
};

// Reads the files (any mocap the database builder reads) into world-space body sequences.
std::vector<TruthSequence> load_truth(const std::vector<std::string>& files, double fps);

// A camera that follows the person at a fixed horizontal distance, height and pitch, from a fixed
// yaw in the world (so the person turns relative to it), as a cameraman would.
struct VirtualCamera {
  std::string family;  // "level", "high", "steep", ...
  float yaw_deg = 0.0f;
  float height_m = 1.5f;
  float pitch_deg = 0.0f;  // negative = looking down
  float distance_m = 4.5f;
};

struct Image {
  int width = 1920, height = 1080;
  float horizontal_fov_deg = 60.0f;
};

struct Condition {
  float noise = 0.0f;    // Gaussian σ as a fraction of the 2D bounding-box height
  float dropout = 0.0f;  // chance that a joint (root excepted) is missing
  std::string label() const;
};

// The 2D noise and drop-out of a Condition, applied frame after frame from one random stream.
class InputNoise {
 public:
  explicit InputNoise(std::uint64_t seed) : rng_(seed) {}
  // Adds Gaussian noise of σ = condition.noise × the height of the joints' 2D box to every
  // joint and marks joints other than the root missing with chance condition.dropout.
  void apply(const Condition& condition, recon::BodyXyc& body);

 private:
  std::mt19937_64 rng_;
  std::normal_distribution<float> gauss_{0.0f, 1.0f};
  std::uniform_real_distribution<float> uniform_{0.0f, 1.0f};
};

// One sequence through one camera: the 2D input and the 3D truth in the camera's frame.
struct RenderedSequence {
  std::vector<recon::BodyXyc> input;
  std::vector<Body> truth_camera;  // camera frame, metres
};

// With `input_layout`, the 2D input is rendered in that layout's keypoint definition: the truth's
// canonical joints are moved to where the layout puts its keypoints
// (recon::apply_layout_offsets_3d, direction -1, forward included) before projection; the truth
// stays canonical.
RenderedSequence render(const TruthSequence& sequence, const VirtualCamera& camera,
                        const Image& image, const Condition& condition, std::uint64_t seed,
                        const recon::LayoutOffsets* input_layout = nullptr);

// Errors of one reconstruction against its truth: sums, so results of many sequences add up.
struct Scores {
  double frames = 0, valid = 0;
  double mpjpe_sum = 0, pa_mpjpe_sum = 0;
  double accel_sum = 0, accel_frames = 0;
  double jitter_sum = 0;
  void add(const Scores& o);
  double mpjpe() const { return mpjpe_sum / valid; }
  double pa_mpjpe() const { return pa_mpjpe_sum / valid; }
  double accel() const { return accel_sum / accel_frames; }
  double jitter() const { return jitter_sum / accel_frames; }
  double coverage() const { return valid / frames; }
};

Scores score(const std::vector<recon::Pose3D>& prediction, const std::vector<Body>& truth);

// The default cameras: yaws 0, 45, 90, 135, 180 at four heights/pitches.
std::vector<VirtualCamera> default_cameras(bool quick);
std::vector<Condition> default_conditions(bool quick);

}  // namespace mocap::eval
