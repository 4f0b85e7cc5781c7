#pragma once
// Shared geometry of the detection strategies: a person's box from the keypoints, and the
// removal of duplicates (the same person found by two tiles, two crops or two detectors).

#include <array>
#include <cstddef>
#include <cstdint>
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

// COCO's object keypoint similarity of two people over the keypoints both have: the mean of
// exp(-d² / (2 s² κ²)), d the keypoints' distance, s² the area of `kept`'s box, κ twice COCO's
// per-keypoint σ (0.025 for the nose ... 0.107 for the hips). `common` gets how many keypoints
// both have (0: the similarity is 0).
float keypoint_similarity(const MovenetPerson& kept, const MovenetPerson& other, int& common);

// When two people are one. By default (min_similarity 0): their boxes overlap by more than
// max_iou, or half of the keypoints both have lie within `near` × the kept person's box's larger
// side. With min_similarity > 0, people with at least 3 keypoints in common are one only when
// their keypoint similarity reaches it, however much their boxes overlap (two people embracing or
// crossing stay two); people with fewer in common are compared by box overlap.
struct DuplicateTest {
  float max_iou = 0.5f;
  float near = 0.05f;
  float min_similarity = 0.0f;
};

// Which rule made a person the duplicate of a kept one (none: kept).
enum class DuplicateRule : std::uint8_t { none, box_overlap, same_keypoints, keypoint_similarity };

// People in score order, each dropped when its box overlaps a kept one by more than max_iou or
// when half of the keypoints both have lie within `near` × the kept person's box height.
std::vector<MovenetPerson> remove_duplicates(std::vector<MovenetPerson> people, float max_iou,
                                             float near = 0.05f);
// The same choice as indices into `people`: those kept, best first.
std::vector<std::size_t> distinct_people(std::span<const MovenetPerson> people, float max_iou,
                                         float near = 0.05f);
// The same under `test`; with `why`, per person of `people` the rule that dropped them.
std::vector<std::size_t> distinct_people(std::span<const MovenetPerson> people,
                                         const DuplicateTest& test,
                                         std::vector<DuplicateRule>* why = nullptr);

}  // namespace mocap::detect
