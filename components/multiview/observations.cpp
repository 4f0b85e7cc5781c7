#include "multiview/observations.hpp"

#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

namespace mocap::multiview {

KeypointSet KeypointSet::body15() {
  KeypointSet set;
  set.count = kBodyJoints;
  set.name = "Body15";
  for (int j = 0; j < kBodyJoints; ++j) set.body[j] = JointSource{j, -1, false, ""};
  return set;
}

KeypointSet KeypointSet::of(const KeypointLayout& layout) {
  KeypointSet set;
  set.count = static_cast<int>(layout.keypoints.size());
  set.body = layout.body;
  set.name = layout.name;
  return set;
}

void FrameObservations::reset(int views, int keypoints) {
  if (views < 0 || keypoints <= 0) {
    throw std::invalid_argument("FrameObservations: needs views >= 0 and keypoints > 0");
  }
  keypoints_ = keypoints;
  views_.resize(static_cast<std::size_t>(views));
  for (auto& v : views_) v.clear();
}

std::span<float> FrameObservations::add_person(int view) {
  if (view < 0 || view >= views()) {
    throw std::out_of_range("FrameObservations: view " + std::to_string(view) + " of " +
                            std::to_string(views()));
  }
  std::vector<float>& v = views_[static_cast<std::size_t>(view)];
  const std::size_t start = v.size();
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  for (int k = 0; k < keypoints_; ++k) v.insert(v.end(), {nan, nan, 0.0f});
  return std::span<float>(v).subspan(start, static_cast<std::size_t>(keypoints_) * 3);
}

void FrameObservations::add_person(int view, std::span<const float> xyc) {
  if (xyc.size() != static_cast<std::size_t>(keypoints_) * 3) {
    throw std::invalid_argument("FrameObservations: a person needs " +
                                std::to_string(keypoints_ * 3) + " values, got " +
                                std::to_string(xyc.size()));
  }
  // `xyc` may be a person already in this view (a detection added twice): growing the view moves
  // it, so it is found again by its place.
  std::size_t from = 0;
  bool inside = false;
  if (view >= 0 && view < views()) {  // else add_person(view) says what is wrong
    const std::vector<float>& stored = views_[static_cast<std::size_t>(view)];
    const std::less<const float*> before;
    inside = !stored.empty() && !before(xyc.data(), stored.data()) &&
             before(xyc.data(), stored.data() + stored.size());
    if (inside) from = static_cast<std::size_t>(xyc.data() - stored.data());
  }
  const std::span<float> out = add_person(view);
  const float* source = inside ? views_[static_cast<std::size_t>(view)].data() + from : xyc.data();
  std::copy(source, source + xyc.size(), out.begin());
}

int FrameObservations::people(int view) const {
  return static_cast<int>(views_.at(static_cast<std::size_t>(view)).size() /
                          (static_cast<std::size_t>(keypoints_) * 3));
}

std::span<const float> FrameObservations::person(int view, int index) const {
  if (index < 0 || index >= people(view)) {
    throw std::out_of_range("FrameObservations: person " + std::to_string(index) + " of " +
                            std::to_string(people(view)) + " in view " + std::to_string(view));
  }
  const std::size_t stride = static_cast<std::size_t>(keypoints_) * 3;
  return std::span<const float>(views_[static_cast<std::size_t>(view)])
      .subspan(static_cast<std::size_t>(index) * stride, stride);
}

}  // namespace mocap::multiview
