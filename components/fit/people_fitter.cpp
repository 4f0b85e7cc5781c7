#include "fit/people_fitter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "fit/ground_estimation.hpp"
#include "fit/track_fitters.hpp"

namespace mocap::fit {

struct PeopleFitter::State {
  PeopleFitOptions options;
  GroundEstimator estimator;
  TrackFitters<PeopleFitOptions, FrameInput, LiveFitter, WindowedFitter> tracks;
  std::optional<GroundPlane> ground;
  std::string ground_source;
  bool warming_up = false;        // full mode: the first frames wait for the floor estimate
  std::vector<People3D> warm_up;  // those frames

  explicit State(PeopleFitOptions o)
      : options(std::move(o)),
        estimator([&] {
          GroundEstimationOptions e;
          e.ankle_clearance_m = options.fit.ankle_clearance_m;
          return e;
        }()),
        tracks(options, FrameInput{},
               [this](const FittedFrame& fitted, const std::array<bool, 2>& contact) {
                 if (estimating()) estimator.add(fitted.joints, contact);
               }) {
    if (options.calibrated_ground) {
      set_ground(*options.calibrated_ground, "calibrated");
    } else {
      options.fit.ground.reset();
      warming_up = options.mode == StreamFitMode::full && options.estimate_ground;
    }
  }

  bool estimating() const { return !options.calibrated_ground && options.estimate_ground; }

  void set_ground(const GroundPlane& plane, std::string source) {
    ground = plane;
    ground_source = std::move(source);
    options.fit.ground = plane;
    tracks.set_ground(plane);
  }

  // Re-estimated as fitted feet come in, until the estimate rests on plenty of them.
  void update_ground() {
    if (!estimating() || (ground && estimator.contacts() >= 1000)) return;
    if (const auto estimate = estimator.estimate())
      set_ground(estimate->plane, estimate->normal_from_contacts
                                      ? "estimated from the feet (plane of contacts)"
                                      : "estimated from the feet (upright bodies)");
  }

  FrameInput frame_input(const Person3D& person) const {
    FrameInput in;
    std::array<Keypoint2D, kBodyJoints> keypoints = person.keypoints;
    if (options.undistort) options.undistort(keypoints);
    for (int j = 0; j < kBodyJoints; ++j) {
      const auto [x, y, confidence] = keypoints[static_cast<std::size_t>(j)];
      in.keypoints[static_cast<std::size_t>(3 * j)] = x;
      in.keypoints[static_cast<std::size_t>(3 * j + 1)] = y;
      in.keypoints[static_cast<std::size_t>(3 * j + 2)] = std::isfinite(x + y) ? confidence : 0;
    }
    in.retrieved_valid = true;
    in.retrieved = person.positions;
    const std::int64_t frame = person.provenance.frame;
    if (options.contacts && frame >= 0 && frame <= std::numeric_limits<std::uint32_t>::max())
      in.contact = options.contacts->contact(static_cast<std::uint32_t>(frame));
    return in;
  }

  void release(std::vector<People3D>& out) {
    tracks.release_decided([&](People3D&& frame) { out.push_back(finished(std::move(frame))); });
  }

  People3D finished(People3D frame) const {
    if (ground) frame.has_ground = true, frame.ground = *ground;
    return frame;
  }

  void process(People3D frame, std::vector<People3D>& out) {
    std::vector<int> ids;
    for (const Person3D& person : frame.people)
      if (person.id >= 0) ids.push_back(person.id);
    const std::int64_t t = tracks.hold(std::move(frame), ids);
    for (std::size_t i = 0; i < tracks.frame(t).people.size(); ++i) {
      const int id = tracks.frame(t).people[i].id;
      if (id >= 0) tracks.see(id, t, [&] { return frame_input(tracks.frame(t).people[i]); });
    }
    tracks.end_frame(t);
    update_ground();
    release(out);
  }

  // Full mode, floor to estimate: a first fit of the warm-up frames (one solve per person's
  // stretch of frames, no floor) gives the contacts and bodies of the estimate.
  void probe_ground() {
    std::map<int, std::vector<FrameInput>> stretches;
    std::map<int, std::int64_t> last;  // warm-up frame where each person was seen last
    auto fit_stretch = [&](std::vector<FrameInput>& inputs) {
      if (inputs.empty()) return;
      const FitResult result = fit_sequence(inputs, options.fit);
      add(tracks.stats(), result.stats);
      for (std::size_t i = 0; i < result.frames.size(); ++i)
        if (result.frames[i].valid && result.frames[i].observed)
          estimator.add(result.frames[i].joints, inputs[i].contact);
      inputs.clear();
    };
    for (std::size_t f = 0; f < warm_up.size(); ++f) {
      const auto t = static_cast<std::int64_t>(f);
      for (const Person3D& person : warm_up[f].people) {
        if (person.id < 0) continue;
        auto& inputs = stretches[person.id];
        const auto seen = last.find(person.id);
        if (seen != last.end()) {
          if (seen->second == t) continue;  // the id twice in one frame
          if (t - seen->second > options.max_missed + 1)
            fit_stretch(inputs);  // a new track
          else
            inputs.resize(inputs.size() + static_cast<std::size_t>(t - seen->second - 1));
        }
        inputs.push_back(frame_input(person));
        last[person.id] = t;
      }
    }
    for (auto& [id, inputs] : stretches) fit_stretch(inputs);
    update_ground();
  }

  void end_warm_up(std::vector<People3D>& out) {
    warming_up = false;
    if (!tracks.stopping()) probe_ground();
    for (People3D& frame : warm_up) process(std::move(frame), out);
    warm_up.clear();
    warm_up.shrink_to_fit();
  }
};

PeopleFitter::PeopleFitter(PeopleFitOptions options)
    : state_(std::make_unique<State>(std::move(options))) {}
PeopleFitter::~PeopleFitter() = default;
PeopleFitter::PeopleFitter(PeopleFitter&&) noexcept = default;
PeopleFitter& PeopleFitter::operator=(PeopleFitter&&) noexcept = default;

std::vector<People3D> PeopleFitter::push(People3D frame) {
  State& s = *state_;
  std::vector<People3D> out;
  if (s.warming_up) {
    s.warm_up.push_back(std::move(frame));
    if (s.warm_up.size() >= static_cast<std::size_t>(std::max(1, s.options.window.frames)))
      s.end_warm_up(out);
    return out;
  }
  s.process(std::move(frame), out);
  return out;
}

void PeopleFitter::stop() { state_->tracks.stop(); }

std::vector<People3D> PeopleFitter::finish() {
  State& s = *state_;
  std::vector<People3D> out;
  if (s.warming_up) s.end_warm_up(out);
  s.tracks.finish_all();
  s.tracks.release_all([&](People3D&& frame) { out.push_back(s.finished(std::move(frame))); });
  return out;
}

std::int64_t PeopleFitter::placed() const { return state_->tracks.placed(); }
std::size_t PeopleFitter::held_frames() const {
  return state_->tracks.held_frames() + state_->warm_up.size();
}
const FitStats& PeopleFitter::stats() const { return state_->tracks.stats(); }
std::optional<mocap::GroundPlane> PeopleFitter::ground() const { return state_->ground; }
const std::string& PeopleFitter::ground_source() const { return state_->ground_source; }

const FrameTimes& PeopleFitter::frame_times() const { return state_->tracks.frame_times(); }

std::string PeopleFitter::summary() const {
  const State& s = *state_;
  const std::string times = s.tracks.frame_times().describe("frame");
  return std::to_string(s.tracks.placed()) + " person-frames fitted" +
         (s.ground ? ", floor " + s.ground_source + ": camera " + std::to_string(s.ground->offset) +
                         " m above it"
                   : std::string(", no floor")) +
         (times.empty() ? std::string() : ", " + times);
}

}  // namespace mocap::fit
