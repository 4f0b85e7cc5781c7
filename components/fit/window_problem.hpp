#pragma once
// Internal to mocap_fit: the variables and constant data of the frames of a window, and the one
// function that builds and solves the Ceres problem over them (window_problem.cpp, the only file
// that includes Ceres besides nothing else). Not part of the library's interface.

#include <array>
#include <limits>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "fit/skeleton_fit.hpp"

namespace mocap::fit::detail {

inline constexpr int kBones = kBodyJoints - 1;  // bone j (j < 14) ends at joint j
static_assert(index(Joint::root) == kBones, "the root must be the last joint");

// The bones from the root out to joint j (at most 4), outermost last.
struct Chain {
  int length = 0;
  std::array<int, 4> bone{};
};
Chain chain_to(int joint);

// A frame's variables: root translation (camera frame) and the rotation (angle-axis) of every
// bone away from its reference direction.
struct FrameVars {
  std::array<double, 3> t{};
  std::array<std::array<double, 3>, kBones> w{};
};

// A calibrated view of a frame (multi-view fitting): its keypoints and the camera that saw them,
// placed relative to the frame's variables (x_camera = rotation · x + translation).
struct ViewData {
  recon::BodyXyc keypoints{};       // undistorted pixels
  double sigma_px = 0.0;            // one reprojection sigma in pixels (0: no term)
  std::array<double, 4> pinhole{};  // fx, fy, cx, cy
  std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  // row-major
  std::array<double, 3> translation{};
};

// A frame's constants.
struct FrameData {
  bool observed = false;                           // retrieved pose and keypoints present
  std::array<std::array<double, 3>, kBones> d0{};  // reference bone directions (unit, camera)
  recon::BodyXyc keypoints{};
  double sigma_px = 0.0;            // one reprojection sigma in pixels (0: no reprojection term)
  std::array<double, 4> pinhole{};  // fx, fy, cx, cy of the camera that saw the keypoints
  std::array<bool, 2> contact{};
  // When the frame was taken, in frame periods (its frame number): the smoothness and contact
  // terms take two frames k periods apart as k steps. NaN: one step after the frame before it.
  double time = std::numeric_limits<double>::quiet_NaN();
  bool has_start = false;           // the closed-form translation exists
  std::array<double, 3> start_t{};  // closed-form root translation (camera frame)
  std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  // camera -> world, row-major
  std::array<double, 3> position{};                           // camera centre in the world
  // Multi-view: every camera that saw the person (the variables are then in the world and the
  // single-camera keypoints above are unused: sigma_px 0). Empty for the monocular fit.
  std::vector<ViewData> views;
  // Multi-view: bone directions from elsewhere (the monocular retrieval, unit, world) and their
  // inverse sigmas (0: no term).
  std::array<std::array<double, 3>, kBones> prior_d{};
  std::array<double, kBones> prior_inv_sigma{};
  double prior_robust_rad = 0.0;  // Cauchy scale of those terms (radians of chord); 0: squared
};

using Bones = std::array<double, kBones>;

struct WindowFrame {
  FrameVars* vars;
  const FrameData* data;
  bool constant;  // frozen: anchors the terms of its neighbours, not solved
};

// The last frames a windowed fit emitted (at most two, consecutive, valid), frozen: the next
// window is solved after them, so that its smoothness and contact terms join it continuously to
// what was already emitted (WindowedFitter, MultiViewWindowedFitter).
class FrozenAnchors {
 public:
  // A valid frame was emitted: the newest anchor (the oldest of three leaves).
  void emitted(const FrameVars& vars, const FrameData& data) {
    vars_.push_back(vars), data_.push_back(data);
    if (vars_.size() > 2) vars_.erase(vars_.begin()), data_.erase(data_.begin());
  }
  // An invalid frame was emitted: the next window starts free.
  void clear() { vars_.clear(), data_.clear(); }
  // The anchors, oldest first and constant, at the start of a window's problem.
  void add_to(std::vector<WindowFrame>& problem) {
    for (std::size_t a = 0; a < vars_.size(); ++a) problem.push_back({&vars_[a], &data_[a], true});
  }
  bool empty() const { return vars_.empty(); }
  std::size_t size() const { return vars_.size(); }

 private:
  std::vector<FrameVars> vars_;
  std::vector<FrameData> data_;
};

struct WindowSolve {
  bool solve_bones = false;
  int max_iterations = 20;
  bool velocity_smoothing = false;  // first differences instead of second ones
  double max_seconds = 0.0;         // > 0: the solve stops after this long (a stop's quick solve)
};

struct WindowSummary {
  int iterations = 0;
  int variable_frames = 0;
  double initial_cost = 0.0, final_cost = 0.0;
};

// Builds the problem over `frames` (time order; constant frames first) and solves it in place.
WindowSummary solve_window(std::span<const WindowFrame> frames, Bones& bones,
                           const Bones& initial_bones, const FitOptions& options,
                           const WindowSolve& solve);

// Forward kinematics of one frame: absolute camera-frame joints.
Body joints_of(const FrameVars& vars, const FrameData& data, const Bones& bones);

}  // namespace mocap::fit::detail
