// The bundle adjustment of a rig calibrated from a board (rig_calibration.hpp): camera poses, board
// poses and optionally the intrinsics, against every corner seen. Ceres stays in this file.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include "camera/rig_calibration.hpp"

namespace mocap::camera::rig_calibration_detail {
namespace {

// fx fy cx cy, then OpenCV's rational model k1 k2 p1 p2 k3 k4 k5 k6.
constexpr int kIntrinsics = 12;
using Block6 = std::array<double, 6>;
using IntrinsicBlock = std::array<double, kIntrinsics>;

IntrinsicBlock intrinsic_block(const Camera& c) {
  if (c.fisheye)
    throw std::invalid_argument(c.name + ": a fisheye camera cannot be calibrated here");
  if (c.distortion.size() > 8)
    throw std::invalid_argument(c.name +
                                ": distortion with more than 8 coefficients (thin prism, "
                                "tilt) cannot be calibrated here");
  IntrinsicBlock b{c.fx, c.fy, c.cx, c.cy};
  for (std::size_t i = 0; i < c.distortion.size(); ++i) b[4 + i] = c.distortion[i];
  return b;
}

void store_intrinsics(const IntrinsicBlock& b, Camera& c) {
  c.fx = b[0];
  c.fy = b[1];
  c.cx = b[2];
  c.cy = b[3];
  // The refined model keeps the file's number of coefficients, at least the five refined.
  const std::size_t n = std::max<std::size_t>(c.distortion.size(), 5);
  c.distortion.assign(b.begin() + 4, b.begin() + 4 + static_cast<long>(n));
}

Block6 block(const Pose& p) {
  return {p.rotation[0],    p.rotation[1],    p.rotation[2],
          p.translation[0], p.translation[1], p.translation[2]};
}

Pose pose(const Block6& b) { return {{b[0], b[1], b[2]}, {b[3], b[4], b[5]}}; }

// A world point through a camera's pose and intrinsics (OpenCV's rational model), minus the
// pixel seen.
template <typename T>
void reproject(const T* k, const T* camera, const T* world, const std::array<double, 2>& pixel,
               T* residual, bool square_pixels = false) {
  T local[3];
  ceres::AngleAxisRotatePoint(camera, world, local);
  for (int i = 0; i < 3; ++i) local[i] += camera[3 + i];
  const T x = local[0] / local[2], y = local[1] / local[2];
  const T r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
  const T radial =
      (T(1) + k[4] * r2 + k[5] * r4 + k[8] * r6) / (T(1) + k[9] * r2 + k[10] * r4 + k[11] * r6);
  const T xd = x * radial + T(2) * k[6] * x * y + k[7] * (r2 + T(2) * x * x);
  const T yd = y * radial + k[6] * (r2 + T(2) * y * y) + T(2) * k[7] * x * y;
  residual[0] = k[0] * xd + k[2] - T(pixel[0]);
  residual[1] = (square_pixels ? k[0] : k[1]) * yd + k[3] - T(pixel[1]);
}

// A board corner: board frame -> world -> image.
struct Reprojection {
  std::array<double, 3> object;
  std::array<double, 2> pixel;
  bool square_pixels = false;  // fy is fx

  template <typename T>
  bool operator()(const T* k, const T* camera, const T* board, T* residual) const {
    const T point[3] = {T(object[0]), T(object[1]), T(object[2])};
    T world[3];
    ceres::AngleAxisRotatePoint(board, point, world);
    for (int i = 0; i < 3; ++i) world[i] += board[3 + i];
    reproject(k, camera, world, pixel, residual, square_pixels);
    return true;
  }
};

// A free point seen by a camera, scaled by the sighting's weight.
struct PointReprojection {
  std::array<double, 2> pixel;
  double weight;

  template <typename T>
  bool operator()(const T* k, const T* camera, const T* point, T* residual) const {
    reproject(k, camera, point, pixel, residual);
    residual[0] *= T(weight);
    residual[1] *= T(weight);
    return true;
  }
};

// Two points a shared length apart.
struct LinkResidual {
  double weight;

  template <typename T>
  bool operator()(const T* a, const T* b, const T* length, T* residual) const {
    const T d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    residual[0] =
        T(weight) * (ceres::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + T(1e-12)) - length[0]);
    return true;
  }
};

}  // namespace

void bundle_adjust(BundleProblem& problem, std::vector<double>& errors) {
  std::vector<IntrinsicBlock> intrinsics;
  for (const Camera& c : problem.cameras) intrinsics.push_back(intrinsic_block(c));
  const bool square = problem.refine_intrinsics && problem.square_pixels;
  if (square)
    for (IntrinsicBlock& b : intrinsics) b[0] = b[1] = 0.5 * (b[0] + b[1]);
  std::vector<Block6> cameras, boards;
  for (const Pose& p : problem.camera_poses) cameras.push_back(block(p));
  for (const Pose& p : problem.board_poses) boards.push_back(block(p));

  // Corners are found to a fraction of a pixel: past 1 px (loss_px) an error grows linearly (a
  // wrong corner pulls less before the outlier round drops it). One loss for all the blocks,
  // owned here.
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::HuberLoss loss_function(problem.loss_px);
  ceres::LossFunction* loss = &loss_function;
  ceres::Problem solver(problem_options);
  for (const CornerObservation& o : problem.corners) {
    if (!o.active) continue;
    auto* cost = new ceres::AutoDiffCostFunction<Reprojection, 2, kIntrinsics, 6, 6>(
        new Reprojection{o.object_m, o.pixel, square});
    solver.AddResidualBlock(cost, loss, intrinsics[o.camera].data(), cameras[o.camera].data(),
                            boards[o.frame].data());
  }
  std::vector<std::array<double, 3>>& points = problem.points;
  for (const PointSighting& o : problem.sightings) {
    if (!o.active) continue;
    auto* cost = new ceres::AutoDiffCostFunction<PointReprojection, 2, kIntrinsics, 6, 3>(
        new PointReprojection{o.pixel, o.weight});
    solver.AddResidualBlock(cost, loss, intrinsics[o.camera].data(), cameras[o.camera].data(),
                            points[o.point].data());
  }
  for (const LengthLink& link : problem.links) {
    if (!solver.HasParameterBlock(points[link.a].data()) ||
        !solver.HasParameterBlock(points[link.b].data()))
      continue;
    auto* cost = new ceres::AutoDiffCostFunction<LinkResidual, 1, 3, 3, 1>(
        new LinkResidual{problem.link_weight_px_per_m});
    solver.AddResidualBlock(cost, nullptr, points[link.a].data(), points[link.b].data(),
                            &problem.lengths[link.length]);
  }
  // Every residual added: now each camera's intrinsics are held or refined.
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    if (!solver.HasParameterBlock(intrinsics[c].data())) continue;
    if (problem.refine_intrinsics) {
      // k3 and k4 k5 k6 (the rational model's denominator) stay as given: fitted from a board
      // that fills little of each image they trade against the focal length. p1 p2 too unless
      // asked for (rig_calibration.hpp, RigBoardOptions::tangential_distortion): a decentred lens
      // looks like a shifted principal point, which looks like a turned camera.
      std::vector<int> held{8, 9, 10, 11};
      if (!problem.refine_tangential) held.insert(held.begin(), {6, 7});
      if (square) held.insert(held.begin(), 1);  // fy: unused, fx serves both
      solver.SetManifold(intrinsics[c].data(), new ceres::SubsetManifold(kIntrinsics, held));
    } else {
      solver.SetParameterBlockConstant(intrinsics[c].data());
    }
  }
  if (problem.fixed_length < problem.lengths.size() &&
      solver.HasParameterBlock(&problem.lengths[problem.fixed_length]))
    solver.SetParameterBlockConstant(&problem.lengths[problem.fixed_length]);
  if (solver.HasParameterBlock(cameras[problem.fixed_camera].data()))
    solver.SetParameterBlockConstant(cameras[problem.fixed_camera].data());

  ceres::Solver::Options options;
  // Few cameras, many boards: dense Schur. Many free points, some linked: sparse.
  options.linear_solver_type = problem.points.empty() ? ceres::DENSE_SCHUR : ceres::SPARSE_SCHUR;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-10;
  options.parameter_tolerance = 1e-10;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &solver, &summary);

  for (std::size_t c = 0; c < cameras.size(); ++c) {
    problem.camera_poses[c] = pose(cameras[c]);
    if (!problem.refine_intrinsics) continue;
    if (square) intrinsics[c][1] = intrinsics[c][0];
    store_intrinsics(intrinsics[c], problem.cameras[c]);
  }
  for (std::size_t b = 0; b < boards.size(); ++b) problem.board_poses[b] = pose(boards[b]);

  errors.assign(problem.corners.size() + problem.sightings.size(),
                std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < problem.corners.size(); ++i) {
    const CornerObservation& o = problem.corners[i];
    if (!o.active) continue;
    double r[2];
    Reprojection{o.object_m, o.pixel, square}(intrinsics[o.camera].data(), cameras[o.camera].data(),
                                              boards[o.frame].data(), r);
    errors[i] = std::hypot(r[0], r[1]);
  }
  for (std::size_t i = 0; i < problem.sightings.size(); ++i) {
    const PointSighting& o = problem.sightings[i];
    if (!o.active) continue;
    double r[2];
    PointReprojection{o.pixel, 1.0}(intrinsics[o.camera].data(), cameras[o.camera].data(),
                                    points[o.point].data(), r);
    errors[problem.corners.size() + i] = std::hypot(r[0], r[1]);
  }
}

bool drop_outliers(BundleProblem& problem, const std::vector<double>& errors, double factor,
                   double floor_px) {
  std::vector<double> active;
  for (double e : errors)
    if (std::isfinite(e)) active.push_back(e);
  if (active.empty()) return false;
  std::nth_element(active.begin(), active.begin() + static_cast<long>(active.size() / 2),
                   active.end());
  const double limit = std::max(factor * active[active.size() / 2], floor_px);
  bool dropped = false;
  const std::size_t corners = problem.corners.size();
  for (std::size_t i = 0; i < errors.size(); ++i) {
    if (!std::isfinite(errors[i]) || errors[i] <= limit) continue;
    if (i < corners)
      problem.corners[i].active = false;
    else
      problem.sightings[i - corners].active = false;
    dropped = true;
  }
  return dropped;
}

std::vector<CameraResiduals> camera_residuals(const BundleProblem& problem,
                                              const std::vector<double>& errors) {
  std::vector<CameraResiduals> out(problem.cameras.size());
  std::vector<double> squared(problem.cameras.size(), 0.0);
  const auto count = [&](std::size_t camera, bool active, double error) {
    if (!active) {
      ++out[camera].dropped;
      return;
    }
    ++out[camera].observations;
    squared[camera] += error * error;
  };
  for (std::size_t i = 0; i < problem.corners.size(); ++i)
    count(problem.corners[i].camera, problem.corners[i].active, errors[i]);
  for (std::size_t i = 0; i < problem.sightings.size(); ++i)
    count(problem.sightings[i].camera, problem.sightings[i].active,
          errors[problem.corners.size() + i]);
  for (std::size_t c = 0; c < out.size(); ++c)
    if (out[c].observations > 0) out[c].rms_px = std::sqrt(squared[c] / out[c].observations);
  return out;
}

}  // namespace mocap::camera::rig_calibration_detail
