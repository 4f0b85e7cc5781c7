#pragma once
// Shared geometry of the detection strategies: a person's box from the keypoints, and the
// removal of duplicates (the same person found by two tiles, two crops or two detectors).

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "detect/movenet_decoder.hpp"

namespace mocap::detect {

// How far a box grows beyond its points: each a share of the points' larger extent (height or
// width); `side` on each side.
struct BoxMargins {
  float top = 0, bottom = 0, side = 0;
};

// The box of the points present (NaN-free, confidence > 0) grown by `margins`. Empty (0 × 0 at
// the origin) without points.
Box2D points_box(std::span<const Keypoint2D> points, const BoxMargins& margins);

// The box of the keypoints (or landmarks) present, widened to the whole person: the keypoints
// stop at the eyes, wrists and ankles, so the box grows by `margin` of its larger extent above
// (the top of the head) and half of that below and on each side.
Box2D keypoint_box(std::span<const Keypoint2D> keypoints, float margin);

// `box` cut to the picture [0, width] × [0, height] (a box wholly outside keeps no area).
Box2D clip_box(const Box2D& box, float width, float height);

// People in score order, each dropped when its box overlaps a kept one by more than max_iou or
// when half of the keypoints both have lie within `near` × the kept person's box height.
std::vector<MovenetPerson> remove_duplicates(std::vector<MovenetPerson> people, float max_iou,
                                             float near = 0.05f);
// The same choice as indices into `people`: those kept, best first.
std::vector<std::size_t> distinct_people(std::span<const MovenetPerson> people, float max_iou,
                                         float near = 0.05f);

}  // namespace mocap::detect
