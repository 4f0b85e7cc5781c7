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

Box2D keypoint_box(const std::array<Keypoint2D, kMovenetKeypoints>& keypoints, float margin) {
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

std::vector<MovenetPerson> remove_duplicates(std::vector<MovenetPerson> people, float max_iou,
                                             float near) {
  std::stable_sort(
      people.begin(), people.end(),
      [](const MovenetPerson& a, const MovenetPerson& b) { return a.score > b.score; });
  std::vector<MovenetPerson> kept;
  for (MovenetPerson& p : people) {
    const bool duplicate = std::any_of(kept.begin(), kept.end(), [&](const MovenetPerson& k) {
      return iou(k.box, p.box) > max_iou || same_keypoints(k, p, near);
    });
    if (!duplicate) kept.push_back(std::move(p));
  }
  return kept;
}

}  // namespace mocap::detect
