#pragma once
// Shared geometry of the detection strategies: a person's box from the keypoints, and the
// removal of duplicates (the same person found by two tiles, two crops or two detectors).

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "detect/movenet_decoder.hpp"

namespace mocap::detect {

// The box of the keypoints (or landmarks) present (NaN-free, confidence > 0), widened to the whole
// person: the keypoints stop at the eyes, wrists and ankles, so the box grows by `margin` of its
// height above (the top of the head) and half of that below and on each side. Empty (0 × 0 at the
// origin) without keypoints.
Box2D keypoint_box(std::span<const Keypoint2D> keypoints, float margin);

// People in score order, each dropped when its box overlaps a kept one by more than max_iou or
// when half of the keypoints both have lie within `near` × the kept person's box height.
std::vector<MovenetPerson> remove_duplicates(std::vector<MovenetPerson> people, float max_iou,
                                             float near = 0.05f);
// The same choice as indices into `people`: those kept, best first.
std::vector<std::size_t> distinct_people(std::span<const MovenetPerson> people, float max_iou,
                                         float near = 0.05f);

}  // namespace mocap::detect
