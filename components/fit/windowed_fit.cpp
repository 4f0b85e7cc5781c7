// The windowed full fit (WindowedFitter): overlapping windows of a person's frames, each solved
// after two frozen, already emitted frames; see skeleton_fit.hpp and docs/fitting.md.

#include <algorithm>
#include <cstdint>

#include "fit/frame_setup.hpp"
#include "fit/skeleton_fit.hpp"
#include "fit/window_problem.hpp"

namespace mocap::fit {

using namespace detail;

namespace {

// Frames whose result another window could still change may not be emitted: at least one frame
// of overlap, and at least one frame emitted per window.
WindowOptions checked(WindowOptions w) {
  w.frames = std::max(w.frames, 2);
  w.overlap = std::clamp(w.overlap, 1, w.frames - 1);
  return w;
}

}  // namespace

struct WindowedFitter::State {
  FitOptions options;
  WindowOptions window;
  bool started = false;  // the first window is solved: bone lengths fixed
  Bones bones{}, initial{};
  BoneLengths lengths;  // initial (start) lengths: the closed-form translations use them
  BoneLengths solved_lengths;
  FitStats stats;
  FrozenAnchors anchors;  // the last emitted frames
  // Held frames, oldest first; `warm`: vars hold an earlier window's solution.
  std::vector<FrameInput> inputs;
  std::vector<FrameVars> vars;
  std::vector<bool> warm;
  std::int64_t first = 0;                       // track index of inputs.front()
  std::optional<Body> reference;                // the latest emitted observed retrieved pose ...
  std::int64_t reference_index = -1;            // ... and its track index
  std::optional<std::array<double, 3>> last_t;  // root of the latest emitted valid frame

  std::vector<FittedFrame> solve_and_emit(std::size_t emit, std::size_t solve_count,
                                          const WindowSolve& how, bool solve);
  bool start(std::size_t count);
  std::vector<int> nearest_observed(std::size_t count) const;
};

// Per held frame (the first `count`): the track index of the observed frame whose pose is its
// reference (itself when observed; else the nearer of the previous and the next, the previous on
// a tie, as fit_sequence does); -1: none.
std::vector<int> WindowedFitter::State::nearest_observed(std::size_t count) const {
  std::vector<int> nearest(count, -1);
  std::int64_t previous = reference ? reference_index : -1;
  for (std::size_t i = 0; i < count; ++i) {
    if (observed(inputs[i])) previous = first + static_cast<std::int64_t>(i);
    nearest[i] = static_cast<int>(previous);
  }
  std::int64_t next = -1;
  for (std::size_t i = count; i-- > 0;) {
    const std::int64_t at = first + static_cast<std::int64_t>(i);
    if (observed(inputs[i])) next = at;
    if (next >= 0 && (nearest[i] < 0 || next - at < at - nearest[i]))
      nearest[i] = static_cast<int>(next);
  }
  return nearest;
}

// Before the first window: the bone lengths from the options or the window's retrieved poses.
bool WindowedFitter::State::start(std::size_t count) {
  if (started) return true;
  const BoneLengths b = initial_bones(std::span(inputs).first(count), options);
  if (!usable(b)) return false;
  lengths = solved_lengths = b;
  bones = initial = to_bones(b);
  return true;
}

// Solves the first `solve_count` held frames (after the anchors), emits the first `emit` of them
// and returns those; frames from `solve_count` on that are emitted too are returned invalid.
std::vector<FittedFrame> WindowedFitter::State::solve_and_emit(std::size_t emit,
                                                               std::size_t solve_count,
                                                               const WindowSolve& how, bool solve) {
  const std::size_t n = solve_count;
  std::vector<FrameData> data(n);
  std::vector<bool> valid(n, false);
  const std::vector<int> nearest = nearest_observed(n);
  const bool ready =
      solve && n > 0 &&
      std::any_of(inputs.begin(), inputs.begin() + n, [](const auto& f) { return observed(f); }) &&
      start(n);
  if (ready) {
    // Constants; starting translations of the frames no window has solved yet.
    std::vector<std::optional<std::array<double, 3>>> t0(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Body& ref = nearest[i] < 0 ? inputs[i].retrieved
                        : nearest[i] < first
                            ? *reference
                            : inputs[static_cast<std::size_t>(nearest[i] - first)].retrieved;
      data[i] = frame_data(inputs[i], ref, options);
      if (data[i].observed) {
        if (const auto t = start_translation(inputs[i], lengths, options)) {
          data[i].has_start = true;
          data[i].start_t = {t->x, t->y, t->z};
          t0[i] = data[i].start_t;
        }
      }
      if (warm[i]) t0[i] = vars[i].t;
    }
    // Frames without a translation take the previous one's (the last emitted frame's for the
    // first), then the next one's.
    std::optional<std::array<double, 3>> carry = last_t;
    for (std::size_t i = 0; i < n; ++i) t0[i] ? void(carry = t0[i]) : void(t0[i] = carry);
    carry.reset();
    for (std::size_t i = n; i-- > 0;) t0[i] ? void(carry = t0[i]) : void(t0[i] = carry);
    std::vector<WindowFrame> problem;
    anchors.add_to(problem);
    // Every frame has a reference here (one is observed); the translations exist for all or
    // none (a window where no keypoints give one, before any was emitted: left invalid).
    for (std::size_t i = 0; i < n; ++i) {
      valid[i] = nearest[i] >= 0 && t0[i].has_value();
      if (!valid[i]) continue;
      if (!warm[i]) vars[i] = FrameVars{}, vars[i].t = *t0[i];
      problem.push_back({&vars[i], &data[i], false});
    }
    if (problem.size() > anchors.size()) {
      const auto summary = solve_window(problem, bones, initial, options,
                                        {how.solve_bones && !started && options.solve_bones,
                                         how.max_iterations, false, how.max_seconds});
      started = true;
      solved_lengths = from_bones(bones);
      count(stats, summary);
    }
  }
  std::vector<FittedFrame> out;
  out.reserve(emit);
  for (std::size_t i = 0; i < emit; ++i) {
    const bool ok = i < n && valid[i];
    out.push_back(ok ? output(vars[i], data[i], bones, true) : FittedFrame{});
    if (ok) {
      anchors.emitted(vars[i], data[i]);
      last_t = vars[i].t;
    } else {
      anchors.clear();
    }
    if (observed(inputs[i]))
      reference = inputs[i].retrieved, reference_index = first + static_cast<std::int64_t>(i);
  }
  for (std::size_t i = emit; i < n; ++i) warm[i] = valid[i];
  const auto drop = static_cast<std::ptrdiff_t>(emit);
  inputs.erase(inputs.begin(), inputs.begin() + drop);
  vars.erase(vars.begin(), vars.begin() + drop);
  warm.erase(warm.begin(), warm.begin() + drop);
  first += drop;
  return out;
}

WindowedFitter::WindowedFitter(FitOptions options, WindowOptions window)
    : state_(std::make_unique<State>()) {
  state_->options = std::move(options);
  state_->window = checked(window);
}
WindowedFitter::~WindowedFitter() = default;
WindowedFitter::WindowedFitter(WindowedFitter&&) noexcept = default;
WindowedFitter& WindowedFitter::operator=(WindowedFitter&&) noexcept = default;
void WindowedFitter::set_ground(std::optional<GroundPlane> ground) {
  state_->options.ground = ground;
}
const BoneLengths& WindowedFitter::bones() const { return state_->solved_lengths; }
const FitStats& WindowedFitter::stats() const { return state_->stats; }
std::size_t WindowedFitter::held() const { return state_->inputs.size(); }

std::vector<FittedFrame> WindowedFitter::push(const FrameInput& frame, bool solve) {
  State& s = *state_;
  s.inputs.push_back(frame);
  s.vars.emplace_back();
  s.warm.push_back(false);
  const auto size = static_cast<std::size_t>(s.window.frames);
  if (!solve || s.inputs.size() < size) return {};
  return s.solve_and_emit(size - static_cast<std::size_t>(s.window.overlap), size,
                          {true, s.options.max_iterations, false, 0.0}, true);
}

std::vector<FittedFrame> WindowedFitter::finish(std::optional<SolveBudget> budget) {
  State& s = *state_;
  // Frames after the person's last observed frame are not solved: nothing places them.
  std::size_t solve_count = s.inputs.size();
  while (solve_count > 0 && !observed(s.inputs[solve_count - 1])) --solve_count;
  const bool solve = !budget || (budget->seconds > 0.0 && budget->iterations > 0);
  WindowSolve how{true, s.options.max_iterations, false, 0.0};
  if (budget) how.max_iterations = budget->iterations, how.max_seconds = budget->seconds;
  return s.solve_and_emit(s.inputs.size(), solve_count, how, solve);
}

}  // namespace mocap::fit
