#pragma once
// Skeleton fitting on several calibrated views (issue 19): per person, the 15-joint body with
// constant bone lengths is solved in the rig's world so that its joints project onto the
// person's keypoints in every camera that saw them, moving smoothly, with soft knee limits and
// the ankles above the rig's floor. The same window problem as the monocular fit
// (window_problem.cpp): its variables are in the world instead of a camera's frame, and each
// frame carries one reprojection term per view instead of one. Started from, and held weakly
// near, the triangulated joints of components/multiview (the bone directions' reference and the
// root's start). docs/fitting.md "Several views", docs/multiview.md "Fitting".
//
// Keypoints are given undistorted (camera::Camera::undistort_pixels, as components/multiview
// takes them): the fit uses each camera's pinhole and pose only.

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "camera/camera.hpp"
#include "fit/skeleton_fit.hpp"

namespace mocap::fit {

// One camera's sight of the person at one frame.
struct ViewKeypoints {
  int camera = 0;  // index in MultiViewFitOptions::cameras
  recon::BodyXyc
      keypoints{};  // 15 × (x, y, confidence), undistorted pixels; confidence 0 = missing
};

// Bone directions the fit is drawn towards besides the views (the monocular retrieval's,
// monocular_prior.hpp): per bone b (ending at joint b, b < 14), a unit direction in the world and
// the inverse of its sigma in radians (0: no term for that bone).
struct DirectionPrior {
  std::array<glm::vec3, kBodyJoints - 1> direction{};
  std::array<float, kBodyJoints - 1> inv_sigma{};
  // The bone's reference (start, and the fit's own weak direction prior) is this direction
  // instead of the triangulated one: where the views do not fix the bone.
  std::array<bool, kBodyJoints - 1> reference{};
  // The bone lacked two good views at this frame (MonocularPrior's "few" class, before the
  // run rule of settle_few_view_runs weighs it).
  std::array<bool, kBodyJoints - 1> few{};
  // A Cauchy loss on each bone's term, its scale in radians (of the chord): a retrieval bending
  // or facing the wrong way pulls with a force that falls off beyond this. <= 0: squared.
  float robust_rad = 0.0f;
  bool any() const {
    for (const float w : inv_sigma)
      if (w > 0.0f) return true;
    return false;
  }
};

// One frame of one person.
struct MultiViewFrameInput {
  std::vector<ViewKeypoints> views;  // none: the person was not seen (filled by smoothness)
  // The triangulated joints (world, metres; a non-finite joint was not triangulated), e.g.
  // multiview::FrameResult::body_of. The frame is fitted when its root is triangulated.
  Body triangulated = not_triangulated();
  std::array<bool, 2> contact{};  // right, left ankle in contact with the floor (kFeet order)
  // When the frame set was taken, in frame periods (its frame number: flow.set_limiter numbers
  // its sets with gaps where it dropped some): the smoothness terms take a gap of k periods as k
  // steps. NaN: one period after the frame before it.
  double time = std::numeric_limits<double>::quiet_NaN();
  DirectionPrior prior;  // none by default; a bone never triangulated also starts from it

  static Body not_triangulated();
};

struct MultiViewFitOptions {
  std::vector<camera::Camera> cameras;  // the rig's, in its order
  // Weights, the floor (FitOptions::ground: the rig's floor, world), lag and iterations; its
  // camera is not used. multiview_fit_defaults() sets the weights chosen for several views.
  FitOptions fit;
  // Live mode: the bone lengths are the triangulated medians of the first `bone_frames` observed
  // frames of a track (0: lag + 1), fixed from then on; until then the track's frames are held
  // (a new person's first second comes out after a second, then every frame `lag` frames late).
  // Not used with fit.bones. 30 (1 s at 30 fps): chosen on the train scenes (docs/fitting.md).
  int bone_frames = 30;
};

// FitOptions with the weights chosen on the virtual multi-view scenes of CMU train clips
// (docs/fitting.md "Several views"): the triangulation is a far better start than a monocular
// retrieval, so its directions hold less and the reprojection in every view decides.
FitOptions multiview_fit_defaults();

// The per-bone median of the triangulated bone lengths (bones with both ends triangulated).
BoneLengths triangulated_bone_lengths(std::span<const MultiViewFrameInput> frames);

// Full mode: every frame in one problem, the bone lengths shared and solved (started from the
// triangulated medians, or options.fit.bones). Frames before the first and after the last
// triangulated root are invalid. max_seconds > 0: the solve stops after that long (a stop's
// quick solve).
FitResult fit_multiview_sequence(std::span<const MultiViewFrameInput> frames,
                                 const MultiViewFitOptions& options, double max_seconds = 0.0);

// Full mode in windows (streaming), as WindowedFitter: a track's frames are solved in windows of
// `window.frames` frames as they fill; each window is solved after the two frames emitted before
// it (frozen anchors: its smoothness and contact terms join it continuously to what was emitted),
// and all its frames but the last `window.overlap` are emitted (final); the overlap frames start
// the next window from their solution. The first window solves the bone lengths (from the
// triangulated medians, or options.fit.bones), the next ones keep them. Frames before the
// person's first triangulated root and after the last one held are invalid. A track shorter than
// a window is one solve, the same as fit_multiview_sequence.
class MultiViewWindowedFitter {
 public:
  MultiViewWindowedFitter(MultiViewFitOptions options, WindowOptions window);
  ~MultiViewWindowedFitter();
  MultiViewWindowedFitter(MultiViewWindowedFitter&&) noexcept;
  MultiViewWindowedFitter& operator=(MultiViewWindowedFitter&&) noexcept;

  // Adds the next frame; returns the frames that became final, in order (a window's worth when
  // one was solved). solve = false only holds it (a stop: finish() solves within a budget).
  std::vector<FittedFrame> push(const MultiViewFrameInput& frame, bool solve = true);
  // Every held frame, solved as a last window; with a budget, one quick solve of at most its
  // iterations and time, or none (frames invalid) when its time is out.
  std::vector<FittedFrame> finish(std::optional<SolveBudget> budget = std::nullopt);
  const BoneLengths& bones() const;  // empty until the first window is solved
  const FitStats& stats() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Fixed-lag live mode, as LiveFitter: each push solves the newest lag + 1 frames against the two
// emitted, frozen ones before them and returns the frame that is now `lag` frames old. The bone
// lengths are options.fit.bones, else the triangulated medians of the track's first
// bone_frames observed frames; until those are in, frames are held, then solved together and
// returned at once: every output of a track has the same skeleton.
class MultiViewLiveFitter {
 public:
  explicit MultiViewLiveFitter(MultiViewFitOptions options);
  ~MultiViewLiveFitter();
  MultiViewLiveFitter(MultiViewLiveFitter&&) noexcept;
  MultiViewLiveFitter& operator=(MultiViewLiveFitter&&) noexcept;

  // The frames that became final, in order: none while the bones are not known, then all the
  // frames held, then one per push.
  std::vector<FittedFrame> push(const MultiViewFrameInput& frame);
  std::vector<FittedFrame> finish();  // the frames still held, solved if they never were
  const BoneLengths& bones() const;
  const FitStats& stats() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mocap::fit
