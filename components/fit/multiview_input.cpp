#include "fit/multiview_input.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mocap::fit {

namespace {

// Body joint j of a detection's keypoints (x, y, confidence; confidence 0: missing).
std::array<float, 3> body_joint(std::span<const float> xyc, const JointSource& source) {
  auto at = [&](int k) -> std::array<float, 3> {
    if (k < 0 || static_cast<std::size_t>(3 * k + 2) >= xyc.size()) return {0.0f, 0.0f, 0.0f};
    const float x = xyc[3 * k], y = xyc[3 * k + 1], c = xyc[3 * k + 2];
    if (!multiview::usable_keypoint(x, y, c)) return {0.0f, 0.0f, 0.0f};
    return {x, y, c};
  };
  const auto a = at(source.first);
  if (source.second < 0) return a;
  const auto b = at(source.second);
  if (a[2] > 0 && b[2] > 0)
    return {0.5f * (a[0] + b[0]), 0.5f * (a[1] + b[1]), std::min(a[2], b[2])};
  if (source.either_alone) return a[2] > 0 ? a : b;
  return {0.0f, 0.0f, 0.0f};
}

}  // namespace

void multiview_input(const multiview::FrameObservations& frame,
                     const multiview::FrameResult& result, std::size_t person,
                     const multiview::KeypointSet& set, MultiViewFrameInput& out) {
  out.views.clear();
  out.contact = {};
  const std::span<const int> detections = result.detections_of(person);
  for (std::size_t v = 0; v < detections.size(); ++v) {
    if (detections[v] < 0) continue;
    const std::span<const float> xyc = frame.person(static_cast<int>(v), detections[v]);
    ViewKeypoints& view = out.views.emplace_back();
    view.camera = static_cast<int>(v);
    for (int j = 0; j < kBodyJoints; ++j) {
      const auto k = body_joint(xyc, set.body[static_cast<std::size_t>(j)]);
      for (int i = 0; i < 3; ++i) view.keypoints[3 * j + i] = k[i];
    }
  }
  const std::span<const multiview::TriangulatedPoint> body = result.body_of(person);
  for (int j = 0; j < kBodyJoints; ++j)
    out.triangulated[j] =
        body[j].valid() ? body[j].position : glm::vec3(std::numeric_limits<float>::quiet_NaN());
}

}  // namespace mocap::fit
