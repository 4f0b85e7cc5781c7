// The Ceres side of the fitting: cost functors and the problem set-up. Kept in this one file so
// that Ceres' templates are compiled once and nothing else in the build includes them.

#include "fit/window_problem.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <cmath>
#include <memory>
#include <utility>
#include <vector>

namespace mocap::fit::detail {

Chain chain_to(int joint) {
  Chain c;
  std::array<int, 4> reversed{};
  for (int j = joint; j != index(Joint::root); j = kJointParent[j]) reversed[c.length++] = j;
  for (int i = 0; i < c.length; ++i) c.bone[i] = reversed[c.length - 1 - i];
  return c;
}

namespace {

// Bone direction exp(w) · d0.
template <typename T>
void bone_direction(const T* w, const std::array<double, 3>& d0, T* out) {
  const T d[3] = {T(d0[0]), T(d0[1]), T(d0[2])};
  ceres::AngleAxisRotatePoint(w, d, out);
}

// Joint position in the camera frame: t + Σ L_b · exp(w_b) · d0_b along the chain.
template <typename T>
void chain_position(const T* t, const T* bones, const T* const* w, const Chain& chain,
                    const FrameData& data, T* out) {
  for (int k = 0; k < 3; ++k) out[k] = t[k];
  for (int i = 0; i < chain.length; ++i) {
    T d[3];
    bone_direction(w[i], data.d0[chain.bone[i]], d);
    for (int k = 0; k < 3; ++k) out[k] += bones[chain.bone[i]] * d[k];
  }
}

template <typename T>
void to_world(const FrameData& data, const T* p, T* out) {
  for (int r = 0; r < 3; ++r)
    out[r] = T(data.rotation[3 * r]) * p[0] + T(data.rotation[3 * r + 1]) * p[1] +
             T(data.rotation[3 * r + 2]) * p[2] + T(data.position[r]);
}

// Params: t, bones, w of the chain's bones. Residual: weighted pixel error (2).
struct ReprojectionCost {
  const FrameData* data;
  Chain chain;
  double u, v, weight;
  template <typename T>
  bool operator()(T const* const* p, T* r) const {
    T x[3];
    chain_position(p[0], p[1], p + 2, chain, *data, x);
    if (x[2] < T(1e-3)) x[2] = T(1e-3);  // behind the camera: keep finite
    const auto& k = data->pinhole;
    r[0] = (T(k[0]) * x[0] / x[2] + T(k[2]) - T(u)) * T(weight);
    r[1] = (T(k[1]) * x[1] / x[2] + T(k[3]) - T(v)) * T(weight);
    return true;
  }
};

// The same through a calibrated view: the joint is moved into the view's camera first.
struct ViewReprojectionCost {
  const FrameData* data;
  const ViewData* view;
  Chain chain;
  double u, v, weight;
  template <typename T>
  bool operator()(T const* const* p, T* r) const {
    T x[3], c[3];
    chain_position(p[0], p[1], p + 2, chain, *data, x);
    const auto& m = view->rotation;
    for (int row = 0; row < 3; ++row)
      c[row] = T(m[3 * row]) * x[0] + T(m[3 * row + 1]) * x[1] + T(m[3 * row + 2]) * x[2] +
               T(view->translation[row]);
    if (c[2] < T(1e-3)) c[2] = T(1e-3);  // behind the camera: keep finite
    const auto& k = view->pinhole;
    r[0] = (T(k[0]) * c[0] / c[2] + T(k[2]) - T(u)) * T(weight);
    r[1] = (T(k[1]) * c[1] / c[2] + T(k[3]) - T(v)) * T(weight);
    return true;
  }
};

struct TranslationCost {
  std::array<double, 3> start;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* t, T* r) const {
    for (int k = 0; k < 3; ++k) r[k] = (t[k] - T(start[k])) * T(inv_sigma);
    return true;
  }
};

struct PriorCost {
  double inv_sigma;
  template <typename T>
  bool operator()(const T* w, T* r) const {
    for (int k = 0; k < 3; ++k) r[k] = w[k] * T(inv_sigma);
    return true;
  }
};

// A bone's direction exp(w) · d0 away from a direction from elsewhere (the monocular retrieval):
// the chord between the two unit vectors, about the angle when small, at most 2 (a retrieval
// pointing the other way pulls with a bounded force).
struct DirectionCost {
  std::array<double, 3> d0, target;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* w, T* r) const {
    T d[3];
    bone_direction(w, d0, d);
    for (int k = 0; k < 3; ++k) r[k] = (d[k] - T(target[k])) * T(inv_sigma);
    return true;
  }
};

// Second difference of one bone vector in the world (three frames): c = (1, -2, 1); or, with
// c = (0, -1, 1), the first difference of the last two.
using Difference = std::array<double, 3>;
constexpr Difference kAcceleration = {1.0, -2.0, 1.0};
constexpr Difference kVelocity = {0.0, -1.0, 1.0};

// Frames a and b (consecutive in a window) are this many frame periods apart: their times'
// difference, or 1 where a time is unknown or does not increase.
double step(const FrameData& a, const FrameData& b) {
  const double h = b.time - a.time;
  return std::isfinite(h) && h > 0.0 ? h : 1.0;
}

// The difference of three frames h1 and h2 periods apart: the second difference as an
// acceleration per period², or (velocity) the first difference of the last two as a velocity per
// period; weighted by the square root of the time it stands for, so that a gap of k periods costs
// what the k steps of the same motion would. h1 = h2 = 1 gives kAcceleration, kVelocity.
Difference difference(double h1, double h2, bool velocity) {
  if (velocity) return {0.0, -1.0 / std::sqrt(h2), 1.0 / std::sqrt(h2)};
  const double w = std::sqrt(0.5 * (h1 + h2));
  return {w * 2.0 / (h1 * (h1 + h2)), -w * 2.0 / (h1 * h2), w * 2.0 / (h2 * (h1 + h2))};
}

struct BoneAccelCost {
  const FrameData* f[3];
  int bone;
  double scale;  // initial bone length / sigma
  Difference c;
  template <typename T>
  bool operator()(const T* w0, const T* w1, const T* w2, T* r) const {
    const T* w[3] = {w0, w1, w2};
    T world[3][3];
    for (int i = 0; i < 3; ++i) {
      T d[3];
      bone_direction(w[i], f[i]->d0[bone], d);
      for (int row = 0; row < 3; ++row)
        world[i][row] = T(f[i]->rotation[3 * row]) * d[0] + T(f[i]->rotation[3 * row + 1]) * d[1] +
                        T(f[i]->rotation[3 * row + 2]) * d[2];
    }
    for (int k = 0; k < 3; ++k)
      r[k] = (T(c[0]) * world[0][k] + T(c[1]) * world[1][k] + T(c[2]) * world[2][k]) * T(scale);
    return true;
  }
};

struct RootAccelCost {
  const FrameData* f[3];
  double inv_sigma;
  Difference c;
  template <typename T>
  bool operator()(const T* t0, const T* t1, const T* t2, T* r) const {
    T a[3], b[3], e[3];
    to_world(*f[0], t0, a);
    to_world(*f[1], t1, b);
    to_world(*f[2], t2, e);
    for (int k = 0; k < 3; ++k)
      r[k] = (T(c[0]) * a[k] + T(c[1]) * b[k] + T(c[2]) * e[k]) * T(inv_sigma);
    return true;
  }
};

// A knee bends one way only: with the hip axis h (right hip -> left hip), thigh a and shin b,
// dot(a × b, h) >= 0. Params: w of right hip, left hip, knee, ankle bones.
struct KneeCost {
  const FrameData* data;
  int knee, ankle;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* wr, const T* wl, const T* wk, const T* wa, T* r) const {
    T hr[3], hl[3], a[3], b[3];
    bone_direction(wr, data->d0[index(Joint::right_hip)], hr);
    bone_direction(wl, data->d0[index(Joint::left_hip)], hl);
    bone_direction(wk, data->d0[knee], a);
    bone_direction(wa, data->d0[ankle], b);
    const T h[3] = {hl[0] - hr[0], hl[1] - hr[1], hl[2] - hr[2]};
    T c[3];
    ceres::CrossProduct(a, b, c);
    const T norm = ceres::sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2] + T(1e-12));
    const T s = (c[0] * h[0] + c[1] * h[1] + c[2] * h[2]) / norm;
    r[0] = s < T(0.0) ? -s * T(inv_sigma) : T(0.0);
    return true;
  }
};

// A contact foot stays where it is in the world. Params: t0, t1, bones, w chain (frame 0), w
// chain (frame 1).
struct SlideCost {
  const FrameData* f0;
  const FrameData* f1;
  Chain chain;
  double inv_sigma;
  template <typename T>
  bool operator()(T const* const* p, T* r) const {
    T c0[3], c1[3], w0[3], w1[3];
    chain_position(p[0], p[2], p + 3, chain, *f0, c0);
    chain_position(p[1], p[2], p + 3 + chain.length, chain, *f1, c1);
    to_world(*f0, c0, w0);
    to_world(*f1, c1, w1);
    for (int k = 0; k < 3; ++k) r[k] = (w1[k] - w0[k]) * T(inv_sigma);
    return true;
  }
};

// An ankle stays at least `clearance` above the ground; a contact ankle, with `inv_above` > 0,
// also no higher than that. Params: t, bones, w chain.
struct GroundCost {
  const FrameData* data;
  Chain chain;
  GroundPlane plane;
  double clearance, inv_sigma, inv_above;
  template <typename T>
  bool operator()(T const* const* p, T* r) const {
    T c[3], w[3];
    chain_position(p[0], p[1], p + 2, chain, *data, c);
    to_world(*data, c, w);
    const T height = T(plane.normal.x) * w[0] + T(plane.normal.y) * w[1] +
                     T(plane.normal.z) * w[2] + T(plane.offset);
    r[0] = (T(clearance) - height) * T(height < T(clearance) ? inv_sigma : inv_above);
    return true;
  }
};

struct BonePriorCost {
  Bones initial;
  double inv_sigma, inv_symmetry, inv_scale;
  template <typename T>
  bool operator()(const T* bones, T* r) const {
    T total(0.0);
    double total0 = 0.0;
    for (int b = 0; b < kBones; ++b) {
      r[b] = (bones[b] - T(initial[b])) * T(inv_sigma);
      total += bones[b];
      total0 += initial[b];
    }
    // The overall size: monocular 2D cannot tell a larger person further away from a smaller
    // one nearer, and the smoothness terms would shrink the body; the database's size is kept.
    // (Holding each bone near the initial one scaled to the current size instead was tried:
    // better on validation, worse on the held-out clips; docs/fitting.md.)
    r[kBones + 6] = (total / T(total0) - T(1.0)) * T(inv_scale);
    constexpr std::array<std::array<int, 2>, 6> pairs = {
        {{2, 5}, {3, 6}, {4, 7}, {8, 11}, {9, 12}, {10, 13}}};
    for (int i = 0; i < 6; ++i)
      r[kBones + i] = (bones[pairs[i][0]] - bones[pairs[i][1]]) * T(inv_symmetry);
    return true;
  }
};

template <class Functor>
using Dynamic = ceres::DynamicAutoDiffCostFunction<Functor, 8>;

// A bone's rotation w changes the bone's direction d0 only by its part perpendicular to d0: a
// turn about the bone itself moves nothing, and the prior makes it zero at the optimum (the
// smallest rotation taking d0 to a direction turns about an axis perpendicular to d0). So w moves
// in the plane through its value perpendicular to d0: two unknowns per bone instead of three, a
// third fewer in the linear system of every iteration, the same optimum.
class PerpendicularPlane : public ceres::Manifold {
 public:
  explicit PerpendicularPlane(const std::array<double, 3>& d) {
    // e1: d × the axis least aligned with d; e2 = d × e1 (both unit, perpendicular to d).
    const int a = std::abs(d[0]) < std::abs(d[1]) ? (std::abs(d[0]) < std::abs(d[2]) ? 0 : 2)
                                                  : (std::abs(d[1]) < std::abs(d[2]) ? 1 : 2);
    double axis[3] = {0.0, 0.0, 0.0};
    axis[a] = 1.0;
    ceres::CrossProduct(d.data(), axis, e_[0].data());
    const double n = std::sqrt(e_[0][0] * e_[0][0] + e_[0][1] * e_[0][1] + e_[0][2] * e_[0][2]);
    for (double& v : e_[0]) v /= n;
    ceres::CrossProduct(d.data(), e_[0].data(), e_[1].data());
  }
  int AmbientSize() const override { return 3; }
  int TangentSize() const override { return 2; }
  bool Plus(const double* x, const double* delta, double* out) const override {
    for (int r = 0; r < 3; ++r) out[r] = x[r] + delta[0] * e_[0][r] + delta[1] * e_[1][r];
    return true;
  }
  bool PlusJacobian(const double*, double* jacobian) const override {
    for (int r = 0; r < 3; ++r) jacobian[2 * r] = e_[0][r], jacobian[2 * r + 1] = e_[1][r];
    return true;
  }
  bool Minus(const double* y, const double* x, double* out) const override {
    for (int c = 0; c < 2; ++c)
      out[c] = (y[0] - x[0]) * e_[c][0] + (y[1] - x[1]) * e_[c][1] + (y[2] - x[2]) * e_[c][2];
    return true;
  }
  bool MinusJacobian(const double*, double* jacobian) const override {
    for (int c = 0; c < 2; ++c)
      for (int r = 0; r < 3; ++r) jacobian[3 * c + r] = e_[c][r];
    return true;
  }

 private:
  std::array<std::array<double, 3>, 2> e_{};
};

}  // namespace

Body joints_of(const FrameVars& vars, const FrameData& data, const Bones& bones) {
  Body out;
  out[index(Joint::root)] = glm::vec3(vars.t[0], vars.t[1], vars.t[2]);
  for (int j = 0; j < kBones; ++j) {
    const Chain c = chain_to(j);
    std::array<const double*, 4> w{};
    for (int i = 0; i < c.length; ++i) w[i] = vars.w[c.bone[i]].data();
    double p[3];
    chain_position(vars.t.data(), bones.data(), w.data(), c, data, p);
    out[j] = glm::vec3(p[0], p[1], p[2]);
  }
  return out;
}

WindowSummary solve_window(std::span<const WindowFrame> frames, Bones& bones,
                           const Bones& initial_bones, const FitOptions& options,
                           const WindowSolve& solve) {
  const FitWeights& wt = options.weights;
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  const auto robust = std::make_unique<ceres::HuberLoss>(wt.robust);
  // The direction prior's Cauchy losses, one per scale in sigmas (a handful: one per weight class).
  std::vector<std::pair<double, std::unique_ptr<ceres::CauchyLoss>>> cauchy;
  const auto cauchy_loss = [&cauchy](double scale) -> ceres::LossFunction* {
    if (!(scale > 0.0)) return nullptr;
    for (const auto& [s, loss] : cauchy)
      if (s == scale) return loss.get();
    return cauchy.emplace_back(scale, std::make_unique<ceres::CauchyLoss>(scale)).second.get();
  };

  std::array<Chain, kBodyJoints> chains;
  for (int j = 0; j < kBones; ++j) chains[j] = chain_to(j);

  problem.AddParameterBlock(bones.data(), kBones);
  for (int b = 0; b < kBones; ++b) problem.SetParameterLowerBound(bones.data(), b, 0.02);
  bool any_variable = false;
  for (const WindowFrame& f : frames) {
    problem.AddParameterBlock(f.vars->t.data(), 3);
    for (auto& w : f.vars->w) problem.AddParameterBlock(w.data(), 3);
    any_variable |= !f.constant;
  }
  if (!any_variable) return {};

  for (std::size_t i = 0; i < frames.size(); ++i) {
    const WindowFrame& f = frames[i];
    if (f.constant) continue;  // only terms touching a variable frame
    FrameVars& v = *f.vars;
    const FrameData& d = *f.data;
    // Reprojection.
    if (d.observed && d.sigma_px > 0.0) {
      for (int j = 0; j < kBodyJoints; ++j) {
        const double c = d.keypoints[3 * j + 2];
        if (!(c >= wt.min_confidence)) continue;
        auto cost = std::make_unique<Dynamic<ReprojectionCost>>(
            std::make_unique<ReprojectionCost>(ReprojectionCost{&d, chains[j], d.keypoints[3 * j],
                                                                d.keypoints[3 * j + 1],
                                                                std::sqrt(c) / d.sigma_px})
                .release());
        std::vector<double*> blocks = {v.t.data(), bones.data()};
        cost->AddParameterBlock(3);
        cost->AddParameterBlock(kBones);
        for (int k = 0; k < chains[j].length; ++k) {
          cost->AddParameterBlock(3);
          blocks.push_back(v.w[chains[j].bone[k]].data());
        }
        cost->SetNumResiduals(2);
        problem.AddResidualBlock(cost.release(), robust.get(), blocks);
      }
    }
    // Reprojection in every calibrated view (multi-view).
    if (d.observed)
      for (const ViewData& view : d.views) {
        if (!(view.sigma_px > 0.0)) continue;
        for (int j = 0; j < kBodyJoints; ++j) {
          const double c = view.keypoints[3 * j + 2];
          if (!(c >= wt.min_confidence)) continue;
          auto cost = std::make_unique<Dynamic<ViewReprojectionCost>>(
              std::make_unique<ViewReprojectionCost>(
                  ViewReprojectionCost{&d, &view, chains[j], view.keypoints[3 * j],
                                       view.keypoints[3 * j + 1], std::sqrt(c) / view.sigma_px})
                  .release());
          std::vector<double*> blocks = {v.t.data(), bones.data()};
          cost->AddParameterBlock(3);
          cost->AddParameterBlock(kBones);
          for (int k = 0; k < chains[j].length; ++k) {
            cost->AddParameterBlock(3);
            blocks.push_back(v.w[chains[j].bone[k]].data());
          }
          cost->SetNumResiduals(2);
          problem.AddResidualBlock(cost.release(), robust.get(), blocks);
        }
      }
    // Weak prior towards the closed-form translation (depth is weakly observed in 2D).
    if (d.observed && d.has_start)
      problem.AddResidualBlock(std::make_unique<ceres::AutoDiffCostFunction<TranslationCost, 3, 3>>(
                                   std::make_unique<TranslationCost>(
                                       TranslationCost{d.start_t, 1.0 / wt.translation_prior_m})
                                       .release())
                                   .release(),
                               nullptr, v.t.data());
    // Prior towards the retrieved directions (weaker inside a gap).
    const double prior = (d.observed ? 1.0 : 0.3) / wt.prior_rad;
    for (int b = 0; b < kBones; ++b)
      problem.AddResidualBlock(std::make_unique<ceres::AutoDiffCostFunction<PriorCost, 3, 3>>(
                                   std::make_unique<PriorCost>(PriorCost{prior}).release())
                                   .release(),
                               nullptr, v.w[b].data());
    // Directions from elsewhere (multi-view: the monocular prior).
    if (d.observed)
      for (int b = 0; b < kBones; ++b)
        if (d.prior_inv_sigma[b] > 0.0)
          problem.AddResidualBlock(
              std::make_unique<ceres::AutoDiffCostFunction<DirectionCost, 3, 3>>(
                  std::make_unique<DirectionCost>(
                      DirectionCost{d.d0[b], d.prior_d[b], d.prior_inv_sigma[b]})
                      .release())
                  .release(),
              cauchy_loss(d.prior_robust_rad * d.prior_inv_sigma[b]), v.w[b].data());
    // Knees.
    for (const auto& [knee, ankle] :
         {std::pair{index(Joint::right_knee), index(Joint::right_ankle)},
          std::pair{index(Joint::left_knee), index(Joint::left_ankle)}})
      problem.AddResidualBlock(
          std::make_unique<ceres::AutoDiffCostFunction<KneeCost, 1, 3, 3, 3, 3>>(
              std::make_unique<KneeCost>(KneeCost{&d, knee, ankle, 1.0 / wt.knee_limit}).release())
              .release(),
          nullptr, v.w[index(Joint::right_hip)].data(), v.w[index(Joint::left_hip)].data(),
          v.w[knee].data(), v.w[ankle].data());
    // Ground.
    if (options.ground) {
      for (int s = 0; s < 2; ++s) {
        const int foot = kFeet[s];
        const double inv_above =
            d.contact[s] && wt.contact_ground_m > 0 ? 1.0 / wt.contact_ground_m : 0.0;
        auto cost = std::make_unique<Dynamic<GroundCost>>(
            std::make_unique<GroundCost>(GroundCost{&d, chains[foot], *options.ground,
                                                    options.ankle_clearance_m, 1.0 / wt.ground_m,
                                                    inv_above})
                .release());
        std::vector<double*> blocks = {v.t.data(), bones.data()};
        cost->AddParameterBlock(3);
        cost->AddParameterBlock(kBones);
        for (int k = 0; k < chains[foot].length; ++k) {
          cost->AddParameterBlock(3);
          blocks.push_back(v.w[chains[foot].bone[k]].data());
        }
        cost->SetNumResiduals(1);
        problem.AddResidualBlock(cost.release(), nullptr, blocks);
      }
    }
  }
  // Terms over consecutive frames, where at least one of them is variable.
  for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
    const WindowFrame& a = frames[i];
    const WindowFrame& b = frames[i + 1];
    if (a.constant && b.constant) continue;
    for (int s = 0; s < 2; ++s) {
      if (!a.data->contact[s] || !b.data->contact[s]) continue;
      const Chain& chain = chains[kFeet[s]];
      // A foot's slide over k periods costs what k steps of it would.
      const double inv_sigma = 1.0 / (wt.slide_m * std::sqrt(step(*a.data, *b.data)));
      auto cost = std::make_unique<Dynamic<SlideCost>>(
          std::make_unique<SlideCost>(SlideCost{a.data, b.data, chain, inv_sigma}).release());
      std::vector<double*> blocks = {a.vars->t.data(), b.vars->t.data(), bones.data()};
      cost->AddParameterBlock(3);
      cost->AddParameterBlock(3);
      cost->AddParameterBlock(kBones);
      for (const WindowFrame* f : {&a, &b})
        for (int k = 0; k < chain.length; ++k) {
          cost->AddParameterBlock(3);
          blocks.push_back(f->vars->w[chain.bone[k]].data());
        }
      cost->SetNumResiduals(3);
      problem.AddResidualBlock(cost.release(), nullptr, blocks);
    }
  }
  // Smoothness: accelerations, or velocities when only the newest frame is free (live, lag 0:
  // anchoring it by the acceleration to two frozen frames extrapolates their motion).
  const double root_sigma = solve.velocity_smoothing ? wt.root_velocity_m : wt.root_accel_m;
  const double bone_sigma = solve.velocity_smoothing ? wt.bone_velocity_m : wt.bone_accel_m;
  for (std::size_t i = 0; i + 2 < frames.size(); ++i) {
    const WindowFrame* f[3] = {&frames[i], &frames[i + 1], &frames[i + 2]};
    if (f[0]->constant && f[1]->constant && f[2]->constant) continue;
    const Difference diff = difference(step(*f[0]->data, *f[1]->data),
                                       step(*f[1]->data, *f[2]->data), solve.velocity_smoothing);
    problem.AddResidualBlock(
        std::make_unique<ceres::AutoDiffCostFunction<RootAccelCost, 3, 3, 3, 3>>(
            std::make_unique<RootAccelCost>(
                RootAccelCost{{f[0]->data, f[1]->data, f[2]->data}, 1.0 / root_sigma, diff})
                .release())
            .release(),
        nullptr, f[0]->vars->t.data(), f[1]->vars->t.data(), f[2]->vars->t.data());
    for (int b = 0; b < kBones; ++b)
      problem.AddResidualBlock(
          std::make_unique<ceres::AutoDiffCostFunction<BoneAccelCost, 3, 3, 3, 3>>(
              std::make_unique<BoneAccelCost>(
                  BoneAccelCost{
                      {f[0]->data, f[1]->data, f[2]->data}, b, initial_bones[b] / bone_sigma, diff})
                  .release())
              .release(),
          nullptr, f[0]->vars->w[b].data(), f[1]->vars->w[b].data(), f[2]->vars->w[b].data());
  }
  if (solve.solve_bones) {
    problem.AddResidualBlock(
        std::make_unique<ceres::AutoDiffCostFunction<BonePriorCost, kBones + 7, kBones>>(
            std::make_unique<BonePriorCost>(BonePriorCost{initial_bones, 1.0 / wt.bone_prior_m,
                                                          1.0 / wt.symmetry_m, 1.0 / wt.body_scale})
                .release())
            .release(),
        nullptr, bones.data());
  } else {
    problem.SetParameterBlockConstant(bones.data());
  }
  for (const WindowFrame& f : frames) {
    if (!f.constant) {
      for (int b = 0; b < kBones; ++b)
        problem.SetManifold(f.vars->w[b].data(),
                            std::make_unique<PerpendicularPlane>(f.data->d0[b]).release());
      continue;
    }
    problem.SetParameterBlockConstant(f.vars->t.data());
    for (auto& w : f.vars->w) problem.SetParameterBlockConstant(w.data());
  }

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  // Eigen's simplicial LDLT: twice the speed of SuiteSparse's CHOLMOD on these banded systems of a
  // few thousand unknowns (CHOLMOD's supernodal BLAS calls and OpenMP threads cost more than they
  // save at this size; docs/fitting.md, "Speed").
  so.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  so.max_num_iterations = solve.max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  so.function_tolerance = 1e-5;
  if (solve.max_seconds > 0.0) so.max_solver_time_in_seconds = solve.max_seconds;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  int variable = 0;
  for (const WindowFrame& f : frames) variable += f.constant ? 0 : 1;
  return {static_cast<int>(summary.iterations.size()), variable, summary.initial_cost,
          summary.final_cost};
}

}  // namespace mocap::fit::detail
