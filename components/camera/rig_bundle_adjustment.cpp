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

struct Reprojection {
  std::array<double, 3> object;
  std::array<double, 2> pixel;

  template <typename T>
  bool operator()(const T* k, const T* camera, const T* board, T* residual) const {
    const T point[3] = {T(object[0]), T(object[1]), T(object[2])};
    T world[3], local[3];
    ceres::AngleAxisRotatePoint(board, point, world);
    for (int i = 0; i < 3; ++i) world[i] += board[3 + i];
    ceres::AngleAxisRotatePoint(camera, world, local);
    for (int i = 0; i < 3; ++i) local[i] += camera[3 + i];
    const T x = local[0] / local[2], y = local[1] / local[2];
    const T r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
    const T radial =
        (T(1) + k[4] * r2 + k[5] * r4 + k[8] * r6) / (T(1) + k[9] * r2 + k[10] * r4 + k[11] * r6);
    const T xd = x * radial + T(2) * k[6] * x * y + k[7] * (r2 + T(2) * x * x);
    const T yd = y * radial + k[6] * (r2 + T(2) * y * y) + T(2) * k[7] * x * y;
    residual[0] = k[0] * xd + k[2] - T(pixel[0]);
    residual[1] = k[1] * yd + k[3] - T(pixel[1]);
    return true;
  }
};

}  // namespace

void bundle_adjust(BundleProblem& problem, std::vector<double>& errors) {
  std::vector<IntrinsicBlock> intrinsics;
  for (const Camera& c : problem.cameras) intrinsics.push_back(intrinsic_block(c));
  std::vector<Block6> cameras, boards;
  for (const Pose& p : problem.camera_poses) cameras.push_back(block(p));
  for (const Pose& p : problem.board_poses) boards.push_back(block(p));

  ceres::Problem solver;
  // Corners are found to a fraction of a pixel: past 1 px an error grows linearly (a wrong
  // corner pulls less before the outlier round drops it).
  ceres::LossFunction* loss = new ceres::HuberLoss(1.0);
  for (const CornerObservation& o : problem.corners) {
    if (!o.active) continue;
    auto* cost = new ceres::AutoDiffCostFunction<Reprojection, 2, kIntrinsics, 6, 6>(
        new Reprojection{o.object_m, o.pixel});
    solver.AddResidualBlock(cost, loss, intrinsics[o.camera].data(), cameras[o.camera].data(),
                            boards[o.frame].data());
  }
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    if (!solver.HasParameterBlock(intrinsics[c].data())) continue;
    if (problem.refine_intrinsics) {
      // k3 and k4 k5 k6 (the rational model's denominator) stay as given: fitted from a board
      // that fills little of each image they trade against the focal length.
      solver.SetManifold(intrinsics[c].data(),
                         new ceres::SubsetManifold(kIntrinsics, {8, 9, 10, 11}));
    } else {
      solver.SetParameterBlockConstant(intrinsics[c].data());
    }
  }
  if (solver.HasParameterBlock(cameras[problem.fixed_camera].data()))
    solver.SetParameterBlockConstant(cameras[problem.fixed_camera].data());

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;  // few cameras, many boards
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-10;
  options.parameter_tolerance = 1e-10;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &solver, &summary);

  for (std::size_t c = 0; c < cameras.size(); ++c) {
    problem.camera_poses[c] = pose(cameras[c]);
    if (problem.refine_intrinsics) store_intrinsics(intrinsics[c], problem.cameras[c]);
  }
  for (std::size_t b = 0; b < boards.size(); ++b) problem.board_poses[b] = pose(boards[b]);

  errors.assign(problem.corners.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < problem.corners.size(); ++i) {
    const CornerObservation& o = problem.corners[i];
    if (!o.active) continue;
    double r[2];
    Reprojection{o.object_m, o.pixel}(intrinsics[o.camera].data(), cameras[o.camera].data(),
                                      boards[o.frame].data(), r);
    errors[i] = std::hypot(r[0], r[1]);
  }
}

}  // namespace mocap::camera::rig_calibration_detail
