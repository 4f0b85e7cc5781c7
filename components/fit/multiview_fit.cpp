// Skeleton fitting on several calibrated views: the frames' constants from the views and the
// triangulation, then the window problem of the monocular fit (window_problem.cpp) in the world.

#include "fit/multiview_fit.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "fit/frame_setup.hpp"
#include "fit/window_problem.hpp"

namespace mocap::fit {

using namespace detail;

namespace {

constexpr int kRoot = index(Joint::root);
using Directions = std::array<std::array<double, 3>, kBones>;

bool finite(const glm::vec3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

bool observed(const MultiViewFrameInput& in) {
  return !in.views.empty() && finite(in.triangulated[kRoot]);
}

// The direction of bone b in a triangulated body, when both its ends are there.
std::optional<std::array<double, 3>> bone_direction(const Body& body, int b) {
  const glm::vec3 &a = body[kJointParent[b]], &e = body[b];
  if (!finite(a) || !finite(e)) return std::nullopt;
  const glm::dvec3 v = glm::dvec3(e) - glm::dvec3(a);
  const double len = glm::length(v);
  if (!(len > 1e-3)) return std::nullopt;
  return std::array<double, 3>{v.x / len, v.y / len, v.z / len};
}

// Where a bone points before anything was seen of it: up from the root for the upper body, down
// for the legs (the floor's normal is up; y up without a floor). A weak start, corrected by the
// reprojection; it matters only for a bone never triangulated.
std::array<double, 3> default_direction(int b, const FitOptions& options) {
  const glm::dvec3 up = options.ground ? options.ground->normal : glm::dvec3(0.0, 1.0, 0.0);
  const bool leg = b == index(Joint::right_knee) || b == index(Joint::right_ankle) ||
                   b == index(Joint::left_knee) || b == index(Joint::left_ankle);
  const glm::dvec3 d = leg ? -up : up;
  return {d.x, d.y, d.z};
}

// Bone lengths with a gap filled: a bone never triangulated takes its other side's length, else
// 0.25 m (any positive start: it is solved in full mode and the reprojection places it).
BoneLengths filled(BoneLengths b) {
  constexpr std::array<std::array<int, 2>, 6> pairs = {
      {{2, 5}, {3, 6}, {4, 7}, {8, 11}, {9, 12}, {10, 13}}};
  for (const auto& [r, l] : pairs) {
    if (!(b.m[r] > 0.0) && b.m[l] > 0.0) b.m[r] = b.m[l];
    if (!(b.m[l] > 0.0) && b.m[r] > 0.0) b.m[l] = b.m[r];
  }
  for (int j = 0; j < kBones; ++j)
    if (!(b.m[j] > 0.0) || !std::isfinite(b.m[j])) b.m[j] = 0.25;
  return b;
}

// The person's 2D size in one view (pixels): the larger side of the present keypoints' box.
double size_px(const recon::BodyXyc& k, double min_confidence) {
  double x0 = std::numeric_limits<double>::max(), x1 = -x0, y0 = x0, y1 = -x0;
  int n = 0;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (!(k[3 * j + 2] >= min_confidence) || !std::isfinite(k[3 * j]) ||
        !std::isfinite(k[3 * j + 1]))
      continue;
    x0 = std::min<double>(x0, k[3 * j]), x1 = std::max<double>(x1, k[3 * j]);
    y0 = std::min<double>(y0, k[3 * j + 1]), y1 = std::max<double>(y1, k[3 * j + 1]);
    ++n;
  }
  return n >= 2 ? std::max(x1 - x0, y1 - y0) : 0.0;
}

ViewData view_data(const ViewKeypoints& v, const MultiViewFitOptions& options) {
  if (v.camera < 0 || static_cast<std::size_t>(v.camera) >= options.cameras.size())
    throw std::invalid_argument("multi-view fit: keypoints of camera " + std::to_string(v.camera) +
                                ", the rig has " + std::to_string(options.cameras.size()));
  const camera::Camera& c = options.cameras[static_cast<std::size_t>(v.camera)];
  ViewData out;
  out.keypoints = v.keypoints;
  const double size = size_px(v.keypoints, options.fit.weights.min_confidence);
  out.sigma_px = size > 1.0 && c.has_intrinsics() ? options.fit.weights.reprojection * size : 0.0;
  out.pinhole = {c.fx, c.fy, c.cx, c.cy};
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) out.rotation[3 * row + col] = c.rotation[col][row];
  out.translation = {c.translation.x, c.translation.y, c.translation.z};
  return out;
}

// A frame's constants (world frame: the identity pose) with `directions` as its reference.
FrameData frame_data(const MultiViewFrameInput& in, const Directions& directions,
                     const MultiViewFitOptions& options) {
  FrameData d;
  d.observed = observed(in);
  d.d0 = directions;
  d.time = in.time;
  if (!d.observed) return d;
  d.contact = in.contact;
  const glm::vec3 root = in.triangulated[kRoot];
  d.has_start = true;
  d.start_t = {root.x, root.y, root.z};
  d.views.reserve(in.views.size());
  for (const ViewKeypoints& v : in.views) d.views.push_back(view_data(v, options));
  for (int b = 0; b < kBones; ++b) {
    const glm::vec3& p = in.prior.direction[b];
    const double w = in.prior.inv_sigma[b], len = glm::length(glm::dvec3(p));
    if (!(w > 0.0) || !(len > 0.5) || !std::isfinite(len)) continue;
    d.prior_d[b] = {p.x / len, p.y / len, p.z / len};
    d.prior_inv_sigma[b] = w;
  }
  d.prior_robust_rad = std::max(0.0, static_cast<double>(in.prior.robust_rad));
  return d;
}

// Directions of a frame: the triangulated ones, else (or where the prior says so) the prior's
// (the monocular retrieval), the others from `known` (updated).
Directions directions_of(const MultiViewFrameInput& in, Directions& known) {
  for (int b = 0; b < kBones; ++b) {
    const auto d = bone_direction(in.triangulated, b);
    if (d && !in.prior.reference[b]) {
      known[b] = *d;
    } else if (in.prior.inv_sigma[b] > 0.0f) {
      const glm::dvec3 p = glm::normalize(glm::dvec3(in.prior.direction[b]));
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
        known[b] = {p.x, p.y, p.z};
    }
  }
  return known;
}

Directions default_directions(const FitOptions& options) {
  Directions d{};
  for (int b = 0; b < kBones; ++b) d[b] = default_direction(b, options);
  return d;
}

}  // namespace

Body MultiViewFrameInput::not_triangulated() {
  Body b;
  b.fill(glm::vec3(std::numeric_limits<float>::quiet_NaN()));
  return b;
}

FitOptions multiview_fit_defaults() {
  FitOptions o;
  // Chosen with mocap-bench-multiview --quality on train clips (docs/fitting.md, "Several views").
  o.weights.prior_rad = 0.5;            // triangulated directions: a start more than a prior
  o.weights.translation_prior_m = 0.1;  // the triangulated root is good to a few cm
  o.weights.body_scale = 0.05;          // several views see the size: the median's scale is loose
  o.weights.bone_prior_m = 0.03;
  return o;
}

BoneLengths triangulated_bone_lengths(std::span<const MultiViewFrameInput> frames) {
  std::vector<Body> bodies;
  bodies.reserve(frames.size());
  for (const auto& f : frames) bodies.push_back(f.triangulated);
  return median_bone_lengths(bodies);  // skips bones with a non-finite end
}

FitResult fit_multiview_sequence(std::span<const MultiViewFrameInput> frames,
                                 const MultiViewFitOptions& options, double max_seconds) {
  FitResult result;
  result.frames.resize(frames.size());
  std::size_t first = frames.size(), last = 0;
  for (std::size_t i = 0; i < frames.size(); ++i)
    if (observed(frames[i])) first = std::min(first, i), last = i;
  if (first == frames.size()) return result;
  const FitOptions& fit = options.fit;
  const BoneLengths start =
      fit.bones && usable(*fit.bones) ? *fit.bones : filled(triangulated_bone_lengths(frames));
  result.bones = start;

  // Reference directions: each bone's triangulated direction, else the nearest earlier frame's
  // (the first frames take the first seen one).
  const std::size_t n = last + 1 - first;
  std::vector<Directions> directions(n);
  Directions known = default_directions(fit);
  for (std::size_t i = n; i-- > 0;)  // backwards: the first seen direction of each bone
    for (int b = 0; b < kBones; ++b)
      if (const auto d = bone_direction(frames[first + i].triangulated, b)) known[b] = *d;
  for (std::size_t i = 0; i < n; ++i) directions[i] = directions_of(frames[first + i], known);

  std::vector<FrameData> data(n);
  std::vector<FrameVars> vars(n);
  std::array<double, 3> t{};
  for (std::size_t i = 0; i < n; ++i) {
    data[i] = frame_data(frames[first + i], directions[i], options);
    if (data[i].has_start) t = data[i].start_t;
    vars[i].t = t;  // a frame without a root stays where the body was
  }
  std::vector<WindowFrame> window;
  window.reserve(n);
  for (std::size_t i = 0; i < n; ++i) window.push_back({&vars[i], &data[i], false});
  Bones bones = to_bones(start);
  const Bones initial = bones;
  count(result.stats, solve_window(window, bones, initial, fit,
                                   {fit.solve_bones, fit.max_iterations, false, max_seconds}));
  result.bones = from_bones(bones);
  for (std::size_t i = 0; i < n; ++i)
    result.frames[first + i] = output(vars[i], data[i], bones, true);
  return result;
}

// ---- Full mode in windows ----

struct MultiViewWindowedFitter::State {
  MultiViewFitOptions options;
  WindowOptions window;
  std::optional<Bones> bones;  // solved by the first window, kept by the next ones
  BoneLengths lengths;
  FitStats stats;
  FrozenAnchors anchors;                        // the last emitted frames
  std::optional<std::array<double, 3>> last_t;  // root of the latest emitted valid frame
  // Each bone's direction at the latest emitted frame, and whether a triangulation gave it.
  Directions known{};
  std::array<bool, kBones> seen{};
  // Held frames, oldest first; `warm`: their data and vars are an earlier window's solution.
  std::vector<MultiViewFrameInput> inputs;
  std::vector<FrameData> data;
  std::vector<FrameVars> vars;
  std::vector<bool> warm;

  // The directions a window starts from: the last emitted frame's; a bone not triangulated so
  // far takes its first triangulated direction in the window (as fit_multiview_sequence).
  Directions start_directions() const {
    Directions d = known;
    std::array<bool, kBones> found = seen;
    for (const MultiViewFrameInput& in : inputs)
      for (int b = 0; b < kBones; ++b)
        if (!found[b])
          if (const auto direction = bone_direction(in.triangulated, b))
            d[b] = *direction, found[b] = true;
    return d;
  }

  // Solves the held frames after the anchors (unless !solve), returns the first `emit` of them
  // and forgets those.
  std::vector<FittedFrame> solve_and_emit(std::size_t emit, int iterations, double seconds,
                                          bool solve) {
    const std::size_t n = inputs.size();
    std::vector<bool> valid(n, false);
    std::size_t first = n, last = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (observed(inputs[i])) first = std::min(first, i), last = i;
    if (solve && first < n) {
      if (!anchors.empty()) first = 0;  // a gap after the emitted frames is filled from them
      const FitOptions& fit = options.fit;
      Directions directions = start_directions();
      std::optional<std::array<double, 3>> carry;
      if (!anchors.empty()) carry = last_t;
      std::vector<WindowFrame> problem;
      anchors.add_to(problem);
      for (std::size_t i = 0; i <= last; ++i) {
        directions_of(inputs[i], directions);
        if (i < first) continue;
        if (!warm[i]) {
          data[i] = frame_data(inputs[i], directions, options);
          vars[i] = FrameVars{};
          if (data[i].has_start) carry = data[i].start_t;
          vars[i].t = *carry;  // the first frame solved is observed, or follows an anchor
        }
        carry = vars[i].t;
        valid[i] = true;
        problem.push_back({&vars[i], &data[i], false});
      }
      Bones b = bones ? *bones
                      : to_bones(fit.bones && usable(*fit.bones)
                                     ? *fit.bones
                                     : filled(triangulated_bone_lengths(inputs)));
      const Bones initial = b;
      count(stats, solve_window(problem, b, initial, fit,
                                {!bones && fit.solve_bones, iterations, false, seconds}));
      if (!bones) bones = b, lengths = from_bones(b);
    }
    std::vector<FittedFrame> out;
    out.reserve(emit);
    for (std::size_t i = 0; i < emit; ++i) {
      if (valid[i]) {
        out.push_back(output(vars[i], data[i], *bones, true));
        anchors.emitted(vars[i], data[i]);
        last_t = vars[i].t;
      } else {
        out.emplace_back();
        anchors.clear();
      }
      for (int b = 0; b < kBones; ++b)
        if (const auto d = bone_direction(inputs[i].triangulated, b)) known[b] = *d, seen[b] = true;
    }
    for (std::size_t i = emit; i < n; ++i) warm[i] = valid[i];
    const auto drop = static_cast<std::ptrdiff_t>(emit);
    inputs.erase(inputs.begin(), inputs.begin() + drop);
    data.erase(data.begin(), data.begin() + drop);
    vars.erase(vars.begin(), vars.begin() + drop);
    warm.erase(warm.begin(), warm.begin() + drop);
    return out;
  }
};

MultiViewWindowedFitter::MultiViewWindowedFitter(MultiViewFitOptions options, WindowOptions window)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.options = std::move(options);
  s.window.frames = std::max(window.frames, 2);
  s.window.overlap = std::clamp(window.overlap, 0, s.window.frames - 1);
  s.known = default_directions(s.options.fit);
}
MultiViewWindowedFitter::~MultiViewWindowedFitter() = default;
MultiViewWindowedFitter::MultiViewWindowedFitter(MultiViewWindowedFitter&&) noexcept = default;
MultiViewWindowedFitter& MultiViewWindowedFitter::operator=(MultiViewWindowedFitter&&) noexcept =
    default;
const BoneLengths& MultiViewWindowedFitter::bones() const { return state_->lengths; }
const FitStats& MultiViewWindowedFitter::stats() const { return state_->stats; }

std::vector<FittedFrame> MultiViewWindowedFitter::push(const MultiViewFrameInput& frame,
                                                       bool solve) {
  State& s = *state_;
  s.inputs.push_back(frame);
  s.data.emplace_back();
  s.vars.emplace_back();
  s.warm.push_back(false);
  if (!solve || s.inputs.size() < static_cast<std::size_t>(s.window.frames)) return {};
  return s.solve_and_emit(s.inputs.size() - static_cast<std::size_t>(s.window.overlap),
                          s.options.fit.max_iterations, 0.0, true);
}

std::vector<FittedFrame> MultiViewWindowedFitter::finish(std::optional<SolveBudget> budget) {
  State& s = *state_;
  if (!budget) return s.solve_and_emit(s.inputs.size(), s.options.fit.max_iterations, 0.0, true);
  return s.solve_and_emit(s.inputs.size(), budget->iterations, budget->seconds,
                          budget->seconds > 0.0 && budget->iterations > 0);
}

// ---- Live mode ----

struct MultiViewLiveFitter::State {
  MultiViewFitOptions options;
  bool bones_fixed = false;
  Bones bones{};
  BoneLengths lengths;
  FitStats stats;
  Directions known{};
  std::optional<std::array<double, 3>> last_t;
  std::vector<Body> warm_up;  // triangulated bodies of the observed frames before the bones
  // Frames held: [up to 2 emitted, frozen anchors] [frames not emitted yet: variable]; newest
  // last. Before the bones are fixed every frame is held.
  std::deque<FrameVars> vars;
  std::deque<FrameData> data;
  std::deque<bool> valid;
  std::size_t pushed = 0, emitted = 0, first_held = 0;

  std::size_t bone_frames() const {
    return static_cast<std::size_t>(options.bone_frames > 0 ? options.bone_frames
                                                            : options.fit.lag + 1);
  }

  // Fixes the bone lengths when they are given or enough frames were seen (or `now`).
  void fix_bones(bool now) {
    if (bones_fixed) return;
    const FitOptions& fit = options.fit;
    const bool given = fit.bones && usable(*fit.bones);
    if (!given && (warm_up.empty() || (!now && warm_up.size() < bone_frames()))) return;
    lengths = given ? *fit.bones : filled(median_bone_lengths(warm_up));
    bones = to_bones(lengths);
    bones_fixed = true;
    warm_up = {};
  }

  // Solves the held frames not emitted yet (the valid tail) against the anchors before them.
  void solve() {
    std::size_t begin = vars.size();
    while (begin > 0 && valid[begin - 1]) --begin;
    const std::size_t variable_from = emitted - first_held;
    std::vector<WindowFrame> frames;
    for (std::size_t i = begin; i < vars.size(); ++i)
      frames.push_back({&vars[i], &data[i], i < variable_from});
    if (frames.empty()) return;
    // The first solve after the bones were fixed holds the whole start-up: as many iterations as
    // a full solve.
    const std::size_t variable = vars.size() - std::max(begin, variable_from);
    const int iterations = variable > static_cast<std::size_t>(options.fit.lag) + 1
                               ? options.fit.max_iterations
                               : options.fit.live_iterations;
    count(stats, solve_window(frames, bones, bones, options.fit,
                              {false, iterations, options.fit.lag == 0}));
  }

  void emit_ready(std::vector<FittedFrame>& out, std::size_t keep_back) {
    if (!bones_fixed) return;
    while (emitted + keep_back < pushed) {
      const std::size_t i = emitted - first_held;
      out.push_back(output(vars[i], data[i], bones, valid[i]));
      ++emitted;
    }
    while (first_held + 2 < emitted) {  // two emitted frames stay as anchors
      vars.pop_front();
      data.pop_front();
      valid.pop_front();
      ++first_held;
    }
  }
};

MultiViewLiveFitter::MultiViewLiveFitter(MultiViewFitOptions options)
    : state_(std::make_unique<State>()) {
  state_->options = std::move(options);
  FitOptions& fit = state_->options.fit;
  fit.lag = std::max(0, fit.lag);
  if (fit.weights.live_prior_rad > 0) fit.weights.prior_rad = fit.weights.live_prior_rad;
  state_->known = default_directions(fit);
}
MultiViewLiveFitter::~MultiViewLiveFitter() = default;
MultiViewLiveFitter::MultiViewLiveFitter(MultiViewLiveFitter&&) noexcept = default;
MultiViewLiveFitter& MultiViewLiveFitter::operator=(MultiViewLiveFitter&&) noexcept = default;
const BoneLengths& MultiViewLiveFitter::bones() const { return state_->lengths; }
const FitStats& MultiViewLiveFitter::stats() const { return state_->stats; }

std::vector<FittedFrame> MultiViewLiveFitter::push(const MultiViewFrameInput& frame) {
  State& s = *state_;
  const bool obs = observed(frame);
  FrameData d = frame_data(frame, directions_of(frame, s.known), s.options);
  FrameVars v;
  if (obs) s.last_t = d.start_t;
  if (s.last_t) v.t = obs || s.vars.empty() ? *s.last_t : s.vars.back().t;
  if (obs && !s.bones_fixed) s.warm_up.push_back(frame.triangulated);
  s.data.push_back(std::move(d));
  s.vars.push_back(v);
  s.valid.push_back(s.last_t.has_value());
  ++s.pushed;
  s.fix_bones(false);
  if (s.bones_fixed && s.valid.back()) s.solve();
  std::vector<FittedFrame> out;
  s.emit_ready(out, static_cast<std::size_t>(s.options.fit.lag));
  return out;
}

std::vector<FittedFrame> MultiViewLiveFitter::finish() {
  State& s = *state_;
  std::vector<FittedFrame> out;
  if (!s.bones_fixed) {  // a track shorter than the start-up: one solve of what is held
    s.fix_bones(true);
    if (s.bones_fixed && !s.vars.empty() && s.valid.back()) s.solve();
  }
  if (!s.bones_fixed) {  // nothing was ever observed
    for (; s.emitted < s.pushed; ++s.emitted) out.emplace_back();
    return out;
  }
  s.emit_ready(out, 0);
  return out;
}

}  // namespace mocap::fit
