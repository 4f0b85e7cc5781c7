#include "fit/skeleton_fit.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "fit/frame_setup.hpp"
#include "fit/window_problem.hpp"

namespace mocap::fit {

using namespace detail;

Body FittedFrame::root_relative() const {
  Body out = joints;
  for (auto& j : out) j -= root();
  return out;
}

BoneLengths bone_lengths_of(const Body& pose) {
  BoneLengths out;
  for (int j = 0; j < kBodyJoints; ++j)
    if (kJointParent[j] >= 0) out.m[j] = glm::distance(pose[j], pose[kJointParent[j]]);
  return out;
}

BoneLengths median_bone_lengths(std::span<const Body> poses) {
  BoneLengths out;
  std::vector<double> v;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (kJointParent[j] < 0) continue;
    v.clear();
    for (const Body& p : poses) {
      const double d = glm::distance(p[j], p[kJointParent[j]]);
      if (std::isfinite(d)) v.push_back(d);
    }
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    out.m[j] = v[v.size() / 2];
  }
  return out;
}

std::optional<glm::dvec3> initial_translation(const Body& pose, const recon::BodyXyc& keypoints,
                                              const camera::Camera& camera, double min_confidence) {
  if (!camera.has_intrinsics()) return std::nullopt;
  // Each present joint: tx - u' tz = u' Z - X and ty - v' tz = v' Z - Y.
  glm::dmat3 ata(0.0);
  glm::dvec3 atb(0.0);
  int present = 0;
  for (int j = 0; j < kBodyJoints; ++j) {
    const double c = keypoints[3 * j + 2];
    if (!(c >= min_confidence) || !std::isfinite(keypoints[3 * j]) ||
        !std::isfinite(keypoints[3 * j + 1]))
      continue;
    ++present;
    const double u = (keypoints[3 * j] - camera.cx) / camera.fx;
    const double v = (keypoints[3 * j + 1] - camera.cy) / camera.fy;
    const glm::dvec3 p(pose[j]);
    const glm::dvec3 rows[2] = {{1.0, 0.0, -u}, {0.0, 1.0, -v}};
    const double rhs[2] = {u * p.z - p.x, v * p.z - p.y};
    for (int r = 0; r < 2; ++r) {
      ata += c * glm::outerProduct(rows[r], rows[r]);
      atb += c * rhs[r] * rows[r];
    }
  }
  if (present < 2) return std::nullopt;
  const double det = glm::determinant(ata);
  if (!(std::abs(det) > 1e-12)) return std::nullopt;
  const glm::dvec3 t = glm::inverse(ata) * atb;
  if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z)) return std::nullopt;
  return t;
}

Body with_bone_lengths(const Body& retrieved, const BoneLengths& bones) {
  Body out{};
  out[index(Joint::root)] = retrieved[index(Joint::root)];
  for (int j = 0; j < kBones; ++j) {
    const detail::Chain c = detail::chain_to(j);
    glm::dvec3 p(retrieved[index(Joint::root)]);
    for (int i = 0; i < c.length; ++i) {
      const int b = c.bone[i];
      const glm::dvec3 d = glm::dvec3(retrieved[b]) - glm::dvec3(retrieved[kJointParent[b]]);
      const double len = glm::length(d);
      if (len > 1e-9) p += bones.m[b] * d / len;
    }
    out[j] = glm::vec3(p);
  }
  return out;
}

namespace {

// The person's 2D size (pixels): the larger side of the present keypoints' box.
double person_size_px(const recon::BodyXyc& k, double min_confidence) {
  double x0 = std::numeric_limits<double>::max(), x1 = -x0, y0 = x0, y1 = -x0;
  int n = 0;
  for (int j = 0; j < kBodyJoints; ++j) {
    if (!(k[3 * j + 2] >= min_confidence)) continue;
    if (!std::isfinite(k[3 * j]) || !std::isfinite(k[3 * j + 1])) continue;
    x0 = std::min<double>(x0, k[3 * j]), x1 = std::max<double>(x1, k[3 * j]);
    y0 = std::min<double>(y0, k[3 * j + 1]), y1 = std::max<double>(y1, k[3 * j + 1]);
    ++n;
  }
  return n >= 2 ? std::max(x1 - x0, y1 - y0) : 0.0;
}

bool finite_body(const Body& b) {
  for (const auto& p : b)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
  return true;
}

}  // namespace

namespace detail {

Bones to_bones(const BoneLengths& b) {
  Bones out{};
  for (int j = 0; j < kBones; ++j) out[j] = b.m[j];
  return out;
}

BoneLengths from_bones(const Bones& b) {
  BoneLengths out;
  for (int j = 0; j < kBones; ++j) out.m[j] = b[j];
  return out;
}

bool usable(const BoneLengths& b) {
  for (int j = 0; j < kBones; ++j)
    if (!(b.m[j] > 0.0) || !std::isfinite(b.m[j])) return false;
  return true;
}

bool observed(const FrameInput& in) { return in.retrieved_valid && finite_body(in.retrieved); }

const camera::Camera& camera_of(const FrameInput& in, const FitOptions& options) {
  return in.moving_camera ? *in.moving_camera : options.camera;
}

FrameData frame_data(const FrameInput& in, const Body& reference, const FitOptions& options) {
  FrameData d;
  d.observed = observed(in);
  const Body& pose = d.observed ? in.retrieved : reference;
  for (int b = 0; b < kBones; ++b) {
    glm::dvec3 v = glm::dvec3(pose[b]) - glm::dvec3(pose[kJointParent[b]]);
    const double len = glm::length(v);
    v = len > 1e-9 ? v / len : glm::dvec3(0.0, 1.0, 0.0);
    d.d0[b] = {v.x, v.y, v.z};
  }
  d.keypoints = in.keypoints;
  if (d.observed) {
    const double size = person_size_px(in.keypoints, options.weights.min_confidence);
    d.sigma_px = size > 1.0 ? options.weights.reprojection * size : 0.0;
    d.contact = in.contact;
  }
  const camera::Camera& camera = camera_of(in, options);
  d.pinhole = {camera.fx, camera.fy, camera.cx, camera.cy};
  // camera -> world is the transpose of the camera's world -> camera rotation.
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) d.rotation[3 * row + col] = camera.rotation[row][col];
  const glm::dvec3 centre = camera.centre();
  d.position = {centre.x, centre.y, centre.z};
  return d;
}

FittedFrame output(const FrameVars& v, const FrameData& d, const Bones& bones, bool valid) {
  FittedFrame f;
  f.valid = valid;
  f.observed = d.observed;
  if (valid) f.joints = detail::joints_of(v, d, bones);
  return f;
}

BoneLengths initial_bones(std::span<const FrameInput> frames, const FitOptions& options) {
  if (options.bones && usable(*options.bones)) return *options.bones;
  std::vector<Body> poses;
  for (const auto& f : frames)
    if (observed(f)) poses.push_back(f.retrieved);
  return median_bone_lengths(poses);
}

std::optional<glm::dvec3> start_translation(const FrameInput& in, const BoneLengths& bones,
                                            const FitOptions& options) {
  Body pose = with_bone_lengths(in.retrieved, bones);
  for (auto& p : pose) p -= in.retrieved[index(Joint::root)];
  const auto t = initial_translation(pose, in.keypoints, camera_of(in, options),
                                     options.weights.min_confidence);
  if (t && t->z > 0.1) return t;
  return std::nullopt;
}

void count(FitStats& stats, const WindowSummary& solve) {
  ++stats.solves;
  stats.iterations += solve.iterations;
  stats.frame_iterations += static_cast<double>(solve.variable_frames) * solve.iterations;
  stats.initial_cost += solve.initial_cost;
  stats.final_cost += solve.final_cost;
}

}  // namespace detail

FitResult fit_sequence(std::span<const FrameInput> frames, const FitOptions& options) {
  FitResult result;
  result.frames.resize(frames.size());
  // The nearest observed frame of each frame (its reference pose), earlier one preferred.
  std::vector<int> nearest(frames.size(), -1);
  int last = -1;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (observed(frames[i])) last = static_cast<int>(i);
    nearest[i] = last;
  }
  int next = -1;
  for (std::size_t i = frames.size(); i-- > 0;) {
    if (observed(frames[i])) next = static_cast<int>(i);
    if (nearest[i] < 0 ||
        (next >= 0 && next - static_cast<int>(i) < static_cast<int>(i) - nearest[i]))
      nearest[i] = next;
  }
  if (frames.empty() || nearest[0] < 0) return result;  // nothing observed at all
  const BoneLengths start = initial_bones(frames, options);
  result.bones = start;
  if (!usable(start)) return result;

  std::vector<FrameData> data(frames.size());
  std::vector<FrameVars> vars(frames.size());
  std::vector<std::optional<glm::dvec3>> t0(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    data[i] = frame_data(frames[i], frames[nearest[i]].retrieved, options);
    if (data[i].observed) t0[i] = start_translation(frames[i], start, options);
    if (t0[i]) data[i].has_start = true, data[i].start_t = {t0[i]->x, t0[i]->y, t0[i]->z};
  }
  // Frames without a translation of their own take the nearest one that has one.
  std::optional<glm::dvec3> carry;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (t0[i])
      carry = t0[i];
    else if (carry)
      t0[i] = carry;
  }
  carry.reset();
  for (std::size_t i = frames.size(); i-- > 0;) {
    if (t0[i])
      carry = t0[i];
    else if (carry)
      t0[i] = carry;
  }
  if (!carry) return result;  // no frame gave a translation
  for (std::size_t i = 0; i < frames.size(); ++i) vars[i].t = {t0[i]->x, t0[i]->y, t0[i]->z};

  std::vector<WindowFrame> window;
  for (std::size_t i = 0; i < frames.size(); ++i) window.push_back({&vars[i], &data[i], false});
  Bones bones = to_bones(start);
  const Bones initial = bones;
  const auto summary = detail::solve_window(window, bones, initial, options,
                                            {options.solve_bones, options.max_iterations});
  count(result.stats, summary);
  result.bones = from_bones(bones);
  for (std::size_t i = 0; i < frames.size(); ++i)
    result.frames[i] = output(vars[i], data[i], bones, true);
  return result;
}

// ---- Live mode ----

struct LiveFitter::State {
  FitOptions options;
  bool started = false;
  Bones bones{};
  BoneLengths lengths;
  FitStats stats;
  std::optional<Body> reference;  // the latest observed retrieved pose
  std::optional<glm::dvec3> last_t;
  // Frames held: [frozen anchors (up to 2)] [lag + 1 variable frames]; the newest last.
  std::deque<FrameVars> vars;
  std::deque<FrameData> data;
  std::deque<bool> valid;
  std::size_t pushed = 0, emitted = 0;  // frame counters
  std::size_t first_held = 0;           // frame index of vars.front()
};

LiveFitter::LiveFitter(FitOptions options) : state_(std::make_unique<State>()) {
  state_->options = std::move(options);
  state_->options.lag = std::max(0, state_->options.lag);
  if (state_->options.weights.live_prior_rad > 0)
    state_->options.weights.prior_rad = state_->options.weights.live_prior_rad;
}
LiveFitter::~LiveFitter() = default;
LiveFitter::LiveFitter(LiveFitter&&) noexcept = default;
LiveFitter& LiveFitter::operator=(LiveFitter&&) noexcept = default;
const BoneLengths& LiveFitter::bones() const { return state_->lengths; }
void LiveFitter::set_ground(std::optional<GroundPlane> ground) { state_->options.ground = ground; }
const FitStats& LiveFitter::stats() const { return state_->stats; }

std::optional<FittedFrame> LiveFitter::push(const FrameInput& frame) {
  State& s = *state_;
  const bool obs = observed(frame);
  if (!s.started && obs) {
    BoneLengths b = s.options.bones && usable(*s.options.bones) ? *s.options.bones
                                                                : bone_lengths_of(frame.retrieved);
    if (usable(b)) {
      s.started = true;
      s.lengths = b;
      s.bones = to_bones(b);
    }
  }
  // The new frame's constants and starting values.
  FrameVars v;
  bool valid = false;
  if (obs) s.reference = frame.retrieved;
  std::optional<glm::dvec3> t;
  if (s.started && obs) t = start_translation(frame, s.lengths, s.options);
  if (t) s.last_t = t;
  if (s.started && s.reference && s.last_t) {
    valid = true;
    v.t = {s.last_t->x, s.last_t->y, s.last_t->z};
    if (!t && !s.vars.empty()) v.t = s.vars.back().t;  // a gap: stay where the body was
  }
  s.data.push_back(frame_data(frame, s.reference.value_or(Body{}), s.options));
  if (t) s.data.back().has_start = true, s.data.back().start_t = {t->x, t->y, t->z};
  s.vars.push_back(v);
  s.valid.push_back(valid);
  ++s.pushed;

  // Keep the window: the lag + 1 frames not yet emitted and two emitted (frozen) ones before.
  const std::size_t window = static_cast<std::size_t>(s.options.lag) + 3;
  while (s.vars.size() > window) {
    s.vars.pop_front();
    s.data.pop_front();
    s.valid.pop_front();
    ++s.first_held;
  }
  // Solve the window's valid tail: the frames since the last invalid one.
  std::size_t begin = s.vars.size();
  while (begin > 0 && s.valid[begin - 1]) --begin;
  if (valid) {
    // Frames already emitted are frozen: what was output stays what the next frames connect to.
    const std::size_t held_back = static_cast<std::size_t>(s.options.lag) + 1;
    const std::size_t variable_from = s.vars.size() > held_back ? s.vars.size() - held_back : 0;
    std::vector<WindowFrame> frames;
    for (std::size_t i = begin; i < s.vars.size(); ++i)
      frames.push_back({&s.vars[i], &s.data[i], i < variable_from});
    const auto summary =
        detail::solve_window(frames, s.bones, s.bones, s.options,
                             {false, s.options.live_iterations, s.options.lag == 0});
    count(s.stats, summary);
  }
  // Emit the frame that is now `lag` frames old.
  if (s.pushed <= static_cast<std::size_t>(s.options.lag)) return std::nullopt;
  const std::size_t frame_index = s.pushed - 1 - static_cast<std::size_t>(s.options.lag);
  const std::size_t i = frame_index - s.first_held;
  ++s.emitted;
  return output(s.vars[i], s.data[i], s.bones, s.valid[i]);
}

std::vector<FittedFrame> LiveFitter::finish() {
  State& s = *state_;
  std::vector<FittedFrame> out;
  while (s.emitted < s.pushed) {
    const std::size_t i = s.emitted - s.first_held;
    out.push_back(output(s.vars[i], s.data[i], s.bones, s.valid[i]));
    ++s.emitted;
  }
  return out;
}

}  // namespace mocap::fit
