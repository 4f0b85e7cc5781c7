#pragma once
// Kinematic skeleton fitting after retrieval (issue 7): per person, over a window of frames, the
// 15-joint body's bone rotations, its root translation in the camera frame and its bone lengths
// (shared over time) are solved so that the joints project onto the detected 2D keypoints, stay
// near the retrieved pose, move smoothly, respect soft joint limits, and keep contact feet still
// and above the ground. See docs/fitting.md for the model, the residuals and their weights.
//
// The model: joint j (j != root) sits at p_parent(j) + L_j · R_j · d_j, where d_j is the unit
// direction of bone j in the retrieved pose of that frame (camera frame), R_j = exp(w_j) the
// bone's rotation away from it (the fitted variable) and L_j the person's bone length. The root
// is the translation t. Every output is therefore a skeleton with the person's bone lengths.
//
// Ceres is an implementation detail of skeleton_fit.cpp/window_problem.cpp: nothing here
// includes it.

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "camera/camera.hpp"
#include "core/body15.hpp"
#include "core/ground_plane.hpp"
#include "recon/sequence_reconstruction.hpp"

namespace mocap::fit {

using Body = std::array<glm::vec3, kBodyJoints>;

// Bone lengths of a person: m[j] is the length of the bone kJointParent[j] -> j; m[root] = 0.
struct BoneLengths {
  std::array<double, kBodyJoints> m{};
};

// The bone lengths of one pose, and the per-bone median over the valid poses of a sequence.
BoneLengths bone_lengths_of(const Body& pose);
BoneLengths median_bone_lengths(std::span<const Body> poses);

// Feet of the 15-joint body (the ankles) in the order contact flags use them.
inline constexpr std::array<int, 2> kFeet = {index(Joint::right_ankle), index(Joint::left_ankle)};

// One frame of one person.
struct FrameInput {
  recon::BodyXyc keypoints{};  // 15 × (x, y, confidence) pixels; confidence 0 = missing
  // The retrieved (temporally selected) pose: root-relative joints in the camera frame, metres.
  // Invalid: no retrieval this frame (no detections); the frame is filled by smoothness.
  bool retrieved_valid = false;
  Body retrieved{};
  std::array<bool, 2> contact{};  // right, left ankle in contact with the ground (kFeet order)
  // The camera of this frame when it moves (the virtual protocol's cameras follow the person):
  // its intrinsics and its pose in the world of FitOptions::ground. Absent (the usual static
  // camera, no copy per frame): FitOptions::camera.
  std::optional<camera::Camera> moving_camera;
};

// Standard deviations: each residual is (value / sigma), so a residual of 1 is "one sigma off".
struct FitWeights {
  double reprojection = 0.02;        // fraction of the person's 2D size (larger box side)
  double robust = 2.0;               // Huber threshold, in reprojection sigmas
  double min_confidence = 0.05;      // keypoints below are missing
  double prior_rad = 0.15;           // bone rotation away from the retrieved direction
  double live_prior_rad = 0.0;       // the same in live mode (fixed bones); 0: prior_rad
  double translation_prior_m = 1.0;  // root away from its closed-form start (per axis)
  double bone_accel_m = 0.015;       // bone-vector acceleration (world), metres / frame²
  double root_accel_m = 0.01;        // root acceleration (world), metres / frame²
  double bone_velocity_m = 0.03;     // live, lag 0 only: bone-vector velocity, metres / frame
  double root_velocity_m = 0.03;     // live, lag 0 only: root velocity, metres / frame
  double knee_limit = 0.05;          // sine of a backwards knee bend
  double bone_prior_m = 0.01;        // bone length away from its initial value (full mode)
  double symmetry_m = 0.005;         // left and right bones of a pair
  double body_scale = 0.01;          // the sum of the bones over its initial value, minus 1
  double slide_m = 0.005;            // a contact foot's motion between frames (world), metres
  double ground_m = 0.005;           // an ankle below the ground plus clearance, metres
  double contact_ground_m = 0.0;     // a contact ankle above the ground plus clearance (0: free)
};

struct FitOptions {
  // The camera (intrinsics required) and its pose in the world that `ground` is in; the default
  // pose (identity) makes the camera's frame the world. Only its pinhole is used: keypoints are
  // given undistorted (camera::Camera::undistort_pixels), so the fit never distorts.
  camera::Camera camera;
  std::optional<GroundPlane> ground;  // in the world frame; no penetration term without it
  double ankle_clearance_m = 0.07;    // the ankle joint's height over the sole
  std::optional<BoneLengths> bones;   // initial lengths; the retrieved poses' medians if absent
  bool solve_bones = true;            // full mode: bone lengths are variables (shared)
  FitWeights weights;
  int max_iterations = 30;  // Levenberg-Marquardt iterations per solve
  // Live mode: each new frame is solved together with the `lag` frames before it (not yet
  // emitted); the two frames before those were emitted and are frozen: they anchor the
  // smoothness and contact terms, so an output never changes once given.
  int lag = 3;  // live mode emits frame t once frame t + lag has been solved (0 = no delay)
  int live_iterations = 8;
};

struct FittedFrame {
  bool valid = false;          // a body exists (a frame inside a gap gets one from its neighbours)
  bool observed = false;       // the frame had a retrieved pose
  Body joints{};               // absolute joints in the camera frame, metres
  Body root_relative() const;  // joints - root
  glm::vec3 root() const { return joints[index(Joint::root)]; }
};

struct FitStats {
  int solves = 0;
  int iterations = 0;
  // Σ over solves of (frames solved × iterations): the work, which grows with a window's length
  // times its iterations (a per-frame cost that does not grow with a track's length is linear).
  double frame_iterations = 0.0;
  double initial_cost = 0.0, final_cost = 0.0;  // sums over solves
};

struct FitResult {
  BoneLengths bones;
  std::vector<FittedFrame> frames;
  FitStats stats;
};

// The root translation that makes `pose` (root-relative, camera frame) project onto the 2D
// keypoints best, in closed form: the linear least-squares solution of
// (X_j + t) × ray_j = 0 for every present keypoint, weighted by confidence. nullopt with fewer
// than two present keypoints or a degenerate system.
std::optional<glm::dvec3> initial_translation(const Body& pose, const recon::BodyXyc& keypoints,
                                              const camera::Camera& camera,
                                              double min_confidence = 0.05);

// `retrieved` rebuilt with `bones`: every bone keeps its direction and gets its length.
Body with_bone_lengths(const Body& retrieved, const BoneLengths& bones);

// Full-sequence mode: every frame of `frames` in one problem (bone lengths shared). The reference
// for the windowed mode below (mocap-bench-fit compares them); its cost grows faster than the
// length (docs/fitting.md, "Speed").
FitResult fit_sequence(std::span<const FrameInput> frames, const FitOptions& options);

// Windowed full mode (offline, streaming): a person's frames are solved in overlapping windows of
// `frames` frames; each window is solved after the two frames emitted before it (frozen: they
// anchor the smoothness and contact terms), and all its frames but the last `overlap` are
// emitted: those are final. The overlap frames start the next window from their solution. The
// first window also solves the bone lengths (FitOptions::solve_bones); they are fixed afterwards,
// so every output has the same skeleton. A track shorter than a window is one solve, the same as
// fit_sequence. Cost: linear in the track's length (each frame is solved in at most
// ceil(frames / (frames - overlap)) windows). Chosen on CMU train clips: docs/fitting.md.
struct WindowOptions {
  int frames = 64;
  int overlap = 16;
};

// A limit on a solve: a stop's quick finish. seconds <= 0: nothing is solved (frames invalid).
struct SolveBudget {
  int iterations = 5;
  double seconds = 0.1;
};

class WindowedFitter {
 public:
  explicit WindowedFitter(FitOptions options, WindowOptions window = {});
  ~WindowedFitter();
  WindowedFitter(WindowedFitter&&) noexcept;
  WindowedFitter& operator=(WindowedFitter&&) noexcept;

  // Adds the next frame; returns the frames that became final (in order; usually none, a
  // window's worth when one was solved). solve = false only holds the frame (a stop is under
  // way: finish() solves what is held within a budget).
  std::vector<FittedFrame> push(const FrameInput& frame, bool solve = true);
  // The frames still held, solved as a last window and returned in order; frames after the last
  // observed one are returned invalid, unsolved. With a budget: at most its iterations and time.
  std::vector<FittedFrame> finish(std::optional<SolveBudget> budget = std::nullopt);
  // The floor from now on (a ground estimated while running); nullopt: no ground term.
  void set_ground(std::optional<GroundPlane> ground);
  const BoneLengths& bones() const;  // the initial ones until the first window is solved
  const FitStats& stats() const;
  std::size_t held() const;  // frames pushed and not returned yet

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Fixed-lag live mode: push frames one at a time; each push solves the newest lag + 1 frames
// (warm-started: the held-back frames keep their values, the new one starts from its retrieved
// pose at the closed-form translation) against the frozen, already emitted frames before them,
// and returns the frame that is now `lag` frames old, once there is one. Bone lengths are the
// initial ones throughout (options.bones, else those of the first observed frame's retrieved
// pose) so that every output has the same skeleton.
class LiveFitter {
 public:
  explicit LiveFitter(FitOptions options);
  ~LiveFitter();
  LiveFitter(LiveFitter&&) noexcept;
  LiveFitter& operator=(LiveFitter&&) noexcept;

  std::optional<FittedFrame> push(const FrameInput& frame);
  std::vector<FittedFrame> finish();  // the frames still held back by the lag
  // The floor from now on (a ground estimated while running); nullopt: no ground term.
  void set_ground(std::optional<GroundPlane> ground);
  const BoneLengths& bones() const;
  const FitStats& stats() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mocap::fit
