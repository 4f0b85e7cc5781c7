#pragma once
// The skeleton fit of every person of one stream (the state behind recon.fit): frames of people in
// (People3D from the temporal selector: retrieved poses with their 2D keypoints), the same frames
// out, in order, one output per input frame, with each fitted person placed in the camera frame
// (positions root-relative, root.translation, placed) and the floor once it is known.
//
// Each person id is a track with its own fitter: live (LiveFitter, fixed lag) or full
// (WindowedFitter, overlapping windows). A frame leaves once every person in it is decided
// (recon::HeldFrames). A track ends when its person has been missing for more than `max_missed`
// frames; the same id seen later starts a new track (new bone lengths).
//
// The floor: a calibrated one, else estimated from the fitted feet (GroundEstimator) and refreshed
// until it rests on 1000 contacts. Full mode holds the first `window.frames` frames of the stream
// until a first fit of them (without the floor) has given the estimate, so that the windows, and
// what they emit, have the floor from the start; if those frames cannot give one, the floor comes
// later, as in live mode.
//
// A stop (stop()): no window is solved any more; finish() solves each track's held frames once,
// within a shared budget (stop_budget), and frames beyond it leave unplaced. See docs/fitting.md.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/messages.hpp"
#include "fit/foot_contact.hpp"
#include "fit/frame_times.hpp"
#include "fit/skeleton_fit.hpp"

namespace mocap::fit {

enum class StreamFitMode { live, full };

struct PeopleFitOptions {
  StreamFitMode mode = StreamFitMode::live;
  FitOptions fit;        // camera (required), clearance; lag and live_iterations (live); weights
  WindowOptions window;  // full mode
  int max_missed = 10;   // frames a person may be missing before their track ends
  std::optional<GroundPlane> calibrated_ground;  // the camera's floor (static camera frame)
  bool estimate_ground = true;  // without a calibrated floor: estimate it from the feet
  const ContactDetector* contacts = nullptr;  // the retrieved database frames' foot contact
  // The keypoints as the pinhole camera sees them (a lens' undistortion; missing ones left as
  // they are); empty: unchanged.
  std::function<void(std::array<Keypoint2D, kBodyJoints>&)> undistort;
  SolveBudget stop_budget{5, 0.25};  // a stop's quick solve, for all tracks together
};

class PeopleFitter {
 public:
  explicit PeopleFitter(PeopleFitOptions options);
  ~PeopleFitter();
  PeopleFitter(PeopleFitter&&) noexcept;
  PeopleFitter& operator=(PeopleFitter&&) noexcept;

  // One input frame; returns the frames that are finished now, oldest first (none while they
  // wait for a person's lag or window).
  std::vector<People3D> push(People3D frame);
  // A stop is under way: no long solve from now on (full mode's windows wait for finish()).
  void stop();
  // The end of the stream: every frame still held, in order (after a stop: a quick solve).
  std::vector<People3D> finish();

  std::int64_t placed() const;                       // person-frames placed so far
  std::size_t held_frames() const;                   // input frames not output yet
  const FitStats& stats() const;                     // of every solve so far
  std::optional<mocap::GroundPlane> ground() const;  // the floor (camera frame), once known
  const std::string& ground_source() const;  // "calibrated", "estimated from the feet (...)"
  // How long each input frame took (taken in to pushed into the fitters, solves included).
  const FrameTimes& frame_times() const;
  // "N person-frames fitted, floor SOURCE: camera H m above it" (or ", no floor"), then ", per
  // frame p50 A ms, p95 B ms".
  std::string summary() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mocap::fit
