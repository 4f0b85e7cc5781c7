#include "detect/person_boxes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "detect/centernet.hpp"

namespace mocap::detect {
namespace {

bool present(const Keypoint2D& k) {
  return std::isfinite(k.x) && std::isfinite(k.y) && k.confidence > 0;
}

// Whether most keypoints both people have lie on top of each other.
bool same_keypoints(const MovenetPerson& a, const MovenetPerson& b, float near) {
  const float limit = near * std::max(a.box.height, a.box.width);
  int common = 0, close = 0;
  for (int k = 0; k < kMovenetKeypoints; ++k) {
    if (!present(a.keypoints[k]) || !present(b.keypoints[k])) continue;
    ++common;
    close += std::hypot(a.keypoints[k].x - b.keypoints[k].x, a.keypoints[k].y - b.keypoints[k].y) <=
                     limit
                 ? 1
                 : 0;
  }
  return common >= 3 && 2 * close >= common;
}

}  // namespace

Box2D points_box(std::span<const Keypoint2D> points, const BoxMargins& margins) {
  float x0 = std::numeric_limits<float>::max(), y0 = x0;
  float x1 = std::numeric_limits<float>::lowest(), y1 = x1;
  for (const Keypoint2D& k : points) {
    if (!present(k)) continue;
    x0 = std::min(x0, k.x), x1 = std::max(x1, k.x);
    y0 = std::min(y0, k.y), y1 = std::max(y1, k.y);
  }
  if (x0 > x1) return {};
  const float extent = std::max(y1 - y0, x1 - x0);
  const float top = margins.top * extent, bottom = margins.bottom * extent;
  const float side = margins.side * extent;
  return {x0 - side, y0 - top, (x1 - x0) + 2 * side, (y1 - y0) + top + bottom};
}

Box2D keypoint_box(std::span<const Keypoint2D> keypoints, float margin) {
  // Not points_box(keypoints, {margin, margin / 2, margin / 2}): its sums round differently in the
  // last bit, and the boxes feed the tracking, whose results are compared run against run.
  float x0 = std::numeric_limits<float>::max(), y0 = x0;
  float x1 = std::numeric_limits<float>::lowest(), y1 = x1;
  for (const Keypoint2D& k : keypoints) {
    if (!present(k)) continue;
    x0 = std::min(x0, k.x), x1 = std::max(x1, k.x);
    y0 = std::min(y0, k.y), y1 = std::max(y1, k.y);
  }
  if (x0 > x1) return {};
  const float h = y1 - y0, grow = margin * std::max(h, x1 - x0);
  return {x0 - grow / 2, y0 - grow, (x1 - x0) + grow, h + 1.5f * grow};
}

Box2D clip_box(const Box2D& box, float width, float height) {
  const float x0 = std::clamp(box.x, 0.0f, width), x1 = std::clamp(box.x + box.width, 0.0f, width);
  const float y0 = std::clamp(box.y, 0.0f, height);
  const float y1 = std::clamp(box.y + box.height, 0.0f, height);
  return {x0, y0, x1 - x0, y1 - y0};
}

float keypoint_similarity(const MovenetPerson& kept, const MovenetPerson& other, int& common) {
  // COCO's keypoint σ (cocoeval.py), nose, eyes, ears, shoulders, elbows, wrists, hips, knees,
  // ankles; κ = 2σ.
  constexpr std::array<float, kMovenetKeypoints> kSigma = {
      0.026f, 0.025f, 0.025f, 0.035f, 0.035f, 0.079f, 0.079f, 0.072f, 0.072f,
      0.062f, 0.062f, 0.107f, 0.107f, 0.087f, 0.087f, 0.089f, 0.089f};
  const float area = std::max(kept.box.width * kept.box.height, 1.0f);
  common = 0;
  float sum = 0;
  for (int k = 0; k < kMovenetKeypoints; ++k) {
    const Keypoint2D &a = kept.keypoints[k], &b = other.keypoints[k];
    if (!present(a) || !present(b)) continue;
    ++common;
    const float kappa = 2 * kSigma[static_cast<std::size_t>(k)];
    const float d2 = (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y);
    sum += std::exp(-d2 / (2 * area * kappa * kappa));
  }
  return common > 0 ? sum / static_cast<float>(common) : 0.0f;
}

std::vector<std::size_t> distinct_people(std::span<const MovenetPerson> people,
                                         const DuplicateTest& test,
                                         std::vector<DuplicateRule>* why) {
  std::vector<std::size_t> order(people.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return people[a].score > people[b].score; });
  const auto rule = [&](const MovenetPerson& kept, const MovenetPerson& other) {
    if (test.min_similarity > 0) {
      int common = 0;
      const float similarity = keypoint_similarity(kept, other, common);
      if (common >= 3)
        return similarity >= test.min_similarity ? DuplicateRule::keypoint_similarity
                                                 : DuplicateRule::none;
      return iou(kept.box, other.box) > test.max_iou ? DuplicateRule::box_overlap
                                                     : DuplicateRule::none;
    }
    if (iou(kept.box, other.box) > test.max_iou) return DuplicateRule::box_overlap;
    return same_keypoints(kept, other, test.near) ? DuplicateRule::same_keypoints
                                                  : DuplicateRule::none;
  };
  if (why) why->assign(people.size(), DuplicateRule::none);
  std::vector<std::size_t> kept;
  for (const std::size_t i : order) {
    DuplicateRule dropped = DuplicateRule::none;
    for (const std::size_t k : kept)
      if ((dropped = rule(people[k], people[i])) != DuplicateRule::none) break;
    if (dropped == DuplicateRule::none) kept.push_back(i);
    if (why) (*why)[i] = dropped;
  }
  return kept;
}

std::vector<std::size_t> distinct_people(std::span<const MovenetPerson> people, float max_iou,
                                         float near) {
  return distinct_people(people, DuplicateTest{max_iou, near, 0.0f});
}

std::vector<MovenetPerson> remove_duplicates(std::vector<MovenetPerson> people, float max_iou,
                                             float near) {
  std::vector<MovenetPerson> kept;
  for (const std::size_t i : distinct_people(people, max_iou, near))
    kept.push_back(std::move(people[i]));
  return kept;
}

}  // namespace mocap::detect
