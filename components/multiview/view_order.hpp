#pragma once
// Which camera each view belongs to, among cameras of one image size, by epipolar geometry
// alone (issues 19/20: views given in the wrong order, any permutation, not only one exchange).
// For every pair of views (a, b) and of cameras (i, j) the cost of "view a at camera i and view b
// at camera j" is the median symmetric epipolar distance (undistorted pixels, through cameras i
// and j's intrinsics) of the tallest person's confident joints seen in both, over all frames
// given. An order's cost is the sum over its pairs of views. Up to kExhaustiveUpTo cameras every
// order is tried (8! = 40320 sums of 28 lookups); beyond, exchanges of two views are applied from
// the order given while one lowers the cost (a local optimum). Epipolar distances do not tell a
// pair of cameras from the same pair exchanged (x_j' F x_i = x_i' F' x_j): with two cameras an
// exchange is invisible, with three or more the other cameras tell.

#include <cstddef>
#include <span>
#include <vector>

#include "camera/camera.hpp"
#include "camera/frame_offsets.hpp"

namespace mocap::multiview {

inline constexpr std::size_t kExhaustiveUpTo = 8;

struct ViewOrder {
  // camera_of_view[a]: the camera view a agrees best with (the identity: as given).
  std::vector<std::size_t> camera_of_view;
  double cost_px = 0;        // the order's cost: sum over pairs of median epipolar distances
  double given_cost_px = 0;  // the order given's
};

// `views[a]` are the frames given as camera a's (distorted pixels as read, each frame's tallest
// person used); views only move between cameras of the same image size.
ViewOrder best_view_order(std::span<const camera::Camera> cameras,
                          std::span<const camera::BodySequence> views, double min_confidence);

}  // namespace mocap::multiview
