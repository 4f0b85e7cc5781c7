#pragma once
// The skeleton fit of every person of a multi-view reconstruction (the state behind
// multiview.reconstruct's `fit` and `mocap reconstruct --calibration --fit`): per frame set, the
// reconstruction's People3D (world frame, ids = track ids) with the frame's observations and
// result (components/multiview) in; the same frames out, in order, one output per input, each
// person's 15 joints replaced by the fitted ones (constant bone lengths per track, placed in the
// world). The multi-view counterpart of PeopleFitter (people_fitter.hpp); it lives in
// components/fit beside it because it is fit bookkeeping over fit types, and mocap_fit already
// links mocap_multiview (the node stays an adapter, docs/multiview.md "Fitting in the graph").
//
// Each track id has its own fitter. live: MultiViewLiveFitter (fixed lag; a new track's first
// `bone_frames` observed frames are held until its bone lengths are known, then all leave at
// once). full: MultiViewWindowedFitter, windows of `window.frames` frames per track solved as
// they fill, each after the two frames emitted before it (frozen anchors), the last
// `window.overlap` frames solved again with the next window; a frame leaves when its window is
// solved. A frame leaves once every
// person in it is decided (recon::HeldFrames), so the output is delayed by at most:
//   live: lag frames, or bone_frames + lag frames while a track is new;
//   full: window.frames frames (a person missing longer than `max_missed` frames ends their
//         track, which is solved then).
// A track ends when its person has been missing for more than `max_missed` frames; the same id
// seen later starts a new track (new bone lengths). A person whose root (mid-hip) is not
// triangulated in a frame is not fitted there and keeps the triangulated joints.
//
// A stop (stop()): full mode solves no window any more; finish() solves each track's held frames
// once within a shared budget (`stop_budget`, as PeopleFitter's), frames beyond it leave with
// their triangulated joints: an interrupted run writes every frame within the graph's drain.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/messages.hpp"
#include "fit/frame_times.hpp"
#include "fit/monocular_prior.hpp"
#include "fit/multiview_fit.hpp"
#include "fit/people_fitter.hpp"
#include "multiview/observations.hpp"
#include "multiview/reconstructor.hpp"

namespace mocap::fit {

struct MultiViewPeopleFitOptions {
  StreamFitMode mode = StreamFitMode::live;
  // The rig's cameras, multiview_fit_defaults() weights, the rig's floor (fit.ground), lag and
  // live iterations, bone_frames.
  MultiViewFitOptions fit;
  // Full mode. 300 frames (10 s at 30 fps) bound the delay and a solve's size; 30 frames of
  // overlap smooth the join between windows (a window's first frames are its least constrained).
  WindowOptions window{300, 30};
  int max_missed = 10;               // frames a person may be missing before their track ends
  SolveBudget stop_budget{5, 0.25};  // a stop's quick solve, for all tracks together
  // A pose database (the CMU train split): each person-frame also gets the monocular retrieval's
  // bone directions (fit::MonocularPrior, its options below), strong only where a bone lacked
  // two good views for a run of frames, counted from the past (a frame is pushed before its
  // future is known). Null: no prior.
  std::shared_ptr<const posedb::Database> prior_db;
  MonocularPriorOptions prior;
};

class MultiViewPeopleFitter {
 public:
  explicit MultiViewPeopleFitter(MultiViewPeopleFitOptions options);
  ~MultiViewPeopleFitter();
  MultiViewPeopleFitter(MultiViewPeopleFitter&&) noexcept;
  MultiViewPeopleFitter& operator=(MultiViewPeopleFitter&&) noexcept;

  // One frame set: `frame` is what RigReconstruction (or the caller) made of `result`: its people
  // are the result's, matched by id. `observations` are the set's undistorted keypoints as
  // `result` was computed from them, `set` how they make the 15 body joints. Returns the frames
  // that are finished now, oldest first.
  std::vector<People3D> push(const multiview::FrameObservations& observations,
                             const multiview::FrameResult& result,
                             const multiview::KeypointSet& set, People3D frame);
  // A frame set with nothing to fit (no view yet): held in order like the others.
  std::vector<People3D> push(People3D frame);
  void stop();                     // no long solve from now on
  std::vector<People3D> finish();  // every frame still held, in order

  std::int64_t placed() const;        // person-frames whose joints are the fit's
  std::int64_t prior_frames() const;  // person-frames with a monocular prior
  std::size_t held_frames() const;    // input frames not output yet
  const FitStats& stats() const;
  const FrameTimes& frame_times() const;  // per frame set: taken in to pushed into the fitters
  // "live fit: N of M person-frames fitted, T tracks, per frame set p50 A ms, p95 B ms".
  std::string summary() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mocap::fit
