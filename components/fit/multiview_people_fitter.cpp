#include "fit/multiview_people_fitter.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <optional>

#include "fit/multiview_input.hpp"
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

// Full mode for one track: windows solved as they fill, the first solving the bone lengths.
class WindowedTrack {
 public:
  WindowedTrack(const MultiViewFitOptions& options, WindowOptions window)
      : options_(options), window_(window) {
    window_.frames = std::max(window_.frames, 2);
    window_.overlap = std::clamp(window_.overlap, 0, window_.frames - 1);
  }

  std::vector<FittedFrame> push(const MultiViewFrameInput& in, bool solve) {
    inputs_.push_back(in);
    if (!solve || inputs_.size() < static_cast<std::size_t>(window_.frames)) return {};
    return solve_and_emit(inputs_.size() - static_cast<std::size_t>(window_.overlap),
                          options_.fit.max_iterations, 0.0);
  }

  // Every held frame; with a budget (a stop), one quick solve, none when its time is out.
  std::vector<FittedFrame> finish(std::optional<SolveBudget> budget) {
    if (!budget) return solve_and_emit(inputs_.size(), options_.fit.max_iterations, 0.0);
    if (budget->seconds <= 0.0 || budget->iterations <= 0) {
      std::vector<FittedFrame> unsolved(inputs_.size());
      inputs_.clear();
      return unsolved;
    }
    return solve_and_emit(inputs_.size(), budget->iterations, budget->seconds);
  }

  const FitStats& stats() const { return stats_; }

 private:
  // Solves the held frames, returns the first `emit` of them and forgets those.
  std::vector<FittedFrame> solve_and_emit(std::size_t emit, int iterations, double seconds) {
    if (inputs_.empty()) return {};
    MultiViewFitOptions o = options_;
    o.fit.max_iterations = iterations;
    if (bones_) o.fit.bones = *bones_, o.fit.solve_bones = false;
    FitResult result = fit_multiview_sequence(inputs_, o, seconds);
    add(stats_, result.stats);
    const bool any = std::any_of(result.frames.begin(), result.frames.end(),
                                 [](const FittedFrame& f) { return f.valid; });
    if (any && !bones_) bones_ = result.bones;
    result.frames.resize(emit);
    inputs_.erase(inputs_.begin(), inputs_.begin() + static_cast<std::ptrdiff_t>(emit));
    return std::move(result.frames);
  }

  MultiViewFitOptions options_;
  WindowOptions window_;
  std::vector<MultiViewFrameInput> inputs_;
  std::optional<BoneLengths> bones_;  // solved by the first window, kept by the next ones
  FitStats stats_;
};

}  // namespace

struct MultiViewPeopleFitter::State {
  struct Track {
    std::int64_t next_frame = 0;   // held index of the next frame pushed into the fitter
    std::int64_t next_output = 0;  // held index of the fitter's next output
    std::int64_t last_seen = 0;
    std::optional<MultiViewLiveFitter> live;
    std::optional<WindowedTrack> windowed;
  };

  MultiViewPeopleFitOptions options;
  std::map<int, Track> tracks;
  recon::HeldFrames<People3D> held;
  MultiViewFrameInput input;  // reused
  bool stopping = false;
  std::int64_t placed = 0, people = 0, track_count = 0;
  FitStats stats;

  // A fitter's output for the track's next output frame: placed into that frame (when the
  // person is in it) and the person decided there.
  void place(int id, Track& track, const FittedFrame& fitted) {
    const std::int64_t frame = track.next_output++;
    People3D* out = held.find(frame);
    if (out == nullptr || !held.decide(frame, id)) return;  // absent from that frame
    if (!fitted.valid || !fitted.observed) return;          // keeps the triangulated joints
    for (Person3D& person : out->people) {
      if (person.id != id) continue;
      const glm::vec3 root = fitted.root();
      for (int j = 0; j < kBodyJoints; ++j) person.positions[j] = fitted.joints[j] - root;
      person.root.translation = root;
      person.placed = true;
      ++placed;
    }
  }

  void place_all(int id, Track& track, const std::vector<FittedFrame>& fitted) {
    for (const FittedFrame& f : fitted) place(id, track, f);
  }

  void push(int id, Track& track, const MultiViewFrameInput& in) {
    ++track.next_frame;
    if (track.live)
      place_all(id, track, track.live->push(in));
    else
      place_all(id, track, track.windowed->push(in, !stopping));
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
    ++track_count;
    if (options.mode == StreamFitMode::live)
      track.live.emplace(options.fit);
    else
      track.windowed.emplace(options.fit, options.window);
  }

  const MultiViewFrameInput& empty_input() {
    input.views.clear();
    input.triangulated = MultiViewFrameInput::not_triangulated();
    input.contact = {};
    return input;
  }

  void process(const multiview::FrameObservations* observations,
               const multiview::FrameResult* result, const multiview::KeypointSet* set,
               People3D frame, std::vector<People3D>& out) {
    std::vector<int> ids;
    for (const Person3D& person : frame.people)
      if (person.id >= 0) ids.push_back(person.id);
    std::sort(ids.begin(), ids.end());
    people += static_cast<std::int64_t>(ids.size());
    const std::int64_t t = held.next_index();
    held.hold(std::move(frame), ids);
    if (result) {
      for (std::size_t p = 0; p < result->people.size(); ++p) {
        const int id = result->people[p].id;
        if (id < 0 || !std::binary_search(ids.begin(), ids.end(), id)) continue;
        const auto [it, added] = tracks.try_emplace(id);
        Track& track = it->second;
        if (added) start(track, t);
        if (track.next_frame > t) continue;  // the id twice in one frame: the first one counts
        while (track.next_frame < t) push(id, track, empty_input());  // frames it missed
        multiview_input(*observations, *result, p, *set, input);
        push(id, track, input);
        track.last_seen = t;
      }
    }
    for (auto it = tracks.begin(); it != tracks.end();) {
      Track& track = it->second;
      if (track.next_frame <= t) push(it->first, track, empty_input());  // absent this frame
      if (t - track.last_seen > options.max_missed) {
        finish(it->first, track, std::nullopt);
        it = tracks.erase(it);
      } else {
        ++it;
      }
    }
    held.release_decided([&](People3D&& f) { out.push_back(std::move(f)); });
  }
};

MultiViewPeopleFitter::MultiViewPeopleFitter(MultiViewPeopleFitOptions options)
    : state_(std::make_unique<State>()) {
  state_->options = std::move(options);
}
MultiViewPeopleFitter::~MultiViewPeopleFitter() = default;
MultiViewPeopleFitter::MultiViewPeopleFitter(MultiViewPeopleFitter&&) noexcept = default;
MultiViewPeopleFitter& MultiViewPeopleFitter::operator=(MultiViewPeopleFitter&&) noexcept = default;

std::vector<People3D> MultiViewPeopleFitter::push(const multiview::FrameObservations& observations,
                                                  const multiview::FrameResult& result,
                                                  const multiview::KeypointSet& set,
                                                  People3D frame) {
  std::vector<People3D> out;
  state_->process(&observations, &result, &set, std::move(frame), out);
  return out;
}

std::vector<People3D> MultiViewPeopleFitter::push(People3D frame) {
  std::vector<People3D> out;
  state_->process(nullptr, nullptr, nullptr, std::move(frame), out);
  return out;
}

void MultiViewPeopleFitter::stop() { state_->stopping = true; }

std::vector<People3D> MultiViewPeopleFitter::finish() {
  using Clock = std::chrono::steady_clock;
  State& s = *state_;
  std::vector<People3D> out;
  // After a stop, the tracks share the budget's time: each gets an equal part of what is left;
  // once too little is left for a solve, the rest leave with their triangulated joints.
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
  s.held.release_all([&](People3D&& frame) { out.push_back(std::move(frame)); });
  return out;
}

std::int64_t MultiViewPeopleFitter::placed() const { return state_->placed; }
std::size_t MultiViewPeopleFitter::held_frames() const { return state_->held.size(); }
const FitStats& MultiViewPeopleFitter::stats() const { return state_->stats; }

std::string MultiViewPeopleFitter::summary() const {
  const State& s = *state_;
  return std::string(s.options.mode == StreamFitMode::live ? "live" : "full") +
         " fit: " + std::to_string(s.placed) + " of " + std::to_string(s.people) +
         " person-frames fitted, " + std::to_string(s.track_count) + " tracks";
}

}  // namespace mocap::fit
