#include "fit/people_fitter.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <map>

#include "fit/ground_estimation.hpp"
#include "recon/held_frames.hpp"

namespace mocap::fit {

namespace {

void add(FitStats& total, const FitStats& s) {
  total.solves += s.solves;
  total.iterations += s.iterations;
  total.frame_iterations += s.frame_iterations;
  total.initial_cost += s.initial_cost;
  total.final_cost += s.final_cost;
}

}  // namespace

struct PeopleFitter::State {
  struct Track {
    std::int64_t next_frame = 0;   // stream index of the next frame pushed into the fitter
    std::int64_t next_output = 0;  // stream index of the fitter's next output
    std::int64_t last_seen = 0;
    std::optional<LiveFitter> live;
    std::optional<WindowedFitter> windowed;
    std::deque<std::array<bool, 2>> contacts;  // of the frames pushed and not output yet
  };

  PeopleFitOptions options;
  std::map<int, Track> tracks;
  recon::HeldFrames<People3D> held;
  GroundEstimator estimator;
  std::optional<GroundPlane> ground;
  std::string ground_source;
  bool warming_up = false;        // full mode: the first frames wait for the floor estimate
  std::vector<People3D> warm_up;  // those frames
  bool stopping = false;
  std::int64_t placed = 0;
  FitStats stats;

  explicit State(PeopleFitOptions o)
      : options(std::move(o)), estimator([&] {
          GroundEstimationOptions e;
          e.ankle_clearance_m = options.fit.ankle_clearance_m;
          return e;
        }()) {
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
    for (auto& [id, track] : tracks) {
      if (track.live) track.live->set_ground(plane);
      if (track.windowed) track.windowed->set_ground(plane);
    }
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

  // A fitter's output for the track's next output frame: placed into that frame (when the
  // person is in it) and the person decided there.
  void place(int id, Track& track, const FittedFrame& fitted) {
    const std::int64_t frame = track.next_output++;
    const std::array<bool, 2> contact =
        track.contacts.empty() ? std::array<bool, 2>{} : track.contacts.front();
    if (!track.contacts.empty()) track.contacts.pop_front();
    People3D* out = held.find(frame);
    if (out == nullptr || !held.decide(frame, id)) return;  // absent from that frame
    if (!fitted.valid || !fitted.observed) return;
    for (Person3D& person : out->people) {
      if (person.id != id) continue;
      const glm::vec3 root = fitted.root();
      for (int j = 0; j < kBodyJoints; ++j)
        person.positions[static_cast<std::size_t>(j)] =
            fitted.joints[static_cast<std::size_t>(j)] - root;
      person.root.translation = root;
      person.placed = true;
      ++placed;
      if (estimating()) estimator.add(fitted.joints, contact);
    }
  }

  void place_all(int id, Track& track, const std::vector<FittedFrame>& fitted) {
    for (const FittedFrame& f : fitted) place(id, track, f);
  }

  // One frame of a track: the person as seen, or nullopt (absent: a gap in their window).
  void push(int id, Track& track, const Person3D* person) {
    const FrameInput in = person ? frame_input(*person) : FrameInput{};
    ++track.next_frame;
    track.contacts.push_back(in.contact);
    if (track.live) {
      if (const auto out = track.live->push(in)) place(id, track, *out);
    } else {
      place_all(id, track, track.windowed->push(in, !stopping));
    }
  }

  void finish(int id, Track& track, std::optional<SolveBudget> budget) {
    if (track.live) {
      place_all(id, track, track.live->finish());
      add(stats, track.live->stats());
    } else {
      place_all(id, track, track.windowed->finish(budget));
      add(stats, track.windowed->stats());
    }
  }

  void start(Track& track, std::int64_t t) {
    track.next_frame = track.next_output = track.last_seen = t;
    if (options.mode == StreamFitMode::live)
      track.live.emplace(options.fit);
    else
      track.windowed.emplace(options.fit, options.window);
  }

  void release(std::vector<People3D>& out) {
    held.release_decided([&](People3D&& frame) { out.push_back(finished(std::move(frame))); });
  }

  People3D finished(People3D frame) const {
    if (ground) frame.has_ground = true, frame.ground = *ground;
    return frame;
  }

  void process(People3D frame, std::vector<People3D>& out) {
    std::vector<int> ids;
    for (const Person3D& person : frame.people)
      if (person.id >= 0) ids.push_back(person.id);
    const std::int64_t t = held.next_index();
    held.hold(std::move(frame), ids);
    const People3D& in = *held.find(t);
    for (std::size_t i = 0; i < in.people.size(); ++i) {
      const int id = in.people[i].id;
      if (id < 0) continue;
      const auto [it, added] = tracks.try_emplace(id);
      Track& track = it->second;
      if (added) start(track, t);
      if (track.next_frame > t) continue;  // the id twice in one frame: the first one counts
      while (track.next_frame < t) push(id, track, nullptr);  // frames it missed
      const Person3D person = held.find(t)->people[i];  // a copy: placing may change the frame
      push(id, track, &person);
      track.last_seen = t;
    }
    for (auto it = tracks.begin(); it != tracks.end();) {
      Track& track = it->second;
      if (track.next_frame <= t) push(it->first, track, nullptr);  // absent this frame
      if (t - track.last_seen > options.max_missed) {
        finish(it->first, track, std::nullopt);
        it = tracks.erase(it);
      } else {
        ++it;
      }
    }
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
      add(stats, result.stats);
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
    if (!stopping) probe_ground();
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

void PeopleFitter::stop() { state_->stopping = true; }

std::vector<People3D> PeopleFitter::finish() {
  using Clock = std::chrono::steady_clock;
  State& s = *state_;
  std::vector<People3D> out;
  if (s.warming_up) s.end_warm_up(out);
  // After a stop, the tracks share the budget's time: each gets an equal part of what is left;
  // once too little is left for a solve, the rest leave unplaced.
  const auto start = Clock::now();
  std::size_t left = s.tracks.size();
  for (auto& [id, track] : s.tracks) {
    std::optional<SolveBudget> budget;
    if (s.stopping) {
      const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
      const double share = (s.options.stop_budget.seconds - elapsed) / static_cast<double>(left);
      budget = SolveBudget{s.options.stop_budget.iterations, share >= 0.005 ? share : 0.0};
    }
    s.finish(id, track, budget);
    --left;
  }
  s.tracks.clear();
  s.held.release_all([&](People3D&& frame) { out.push_back(s.finished(std::move(frame))); });
  return out;
}

std::int64_t PeopleFitter::placed() const { return state_->placed; }
std::size_t PeopleFitter::held_frames() const {
  return state_->held.size() + state_->warm_up.size();
}
const FitStats& PeopleFitter::stats() const { return state_->stats; }
std::optional<mocap::GroundPlane> PeopleFitter::ground() const { return state_->ground; }
const std::string& PeopleFitter::ground_source() const { return state_->ground_source; }

std::string PeopleFitter::summary() const {
  const State& s = *state_;
  return std::to_string(s.placed) + " person-frames fitted" +
         (s.ground ? ", floor " + s.ground_source + ": camera " + std::to_string(s.ground->offset) +
                         " m above it"
                   : std::string(", no floor"));
}

}  // namespace mocap::fit
