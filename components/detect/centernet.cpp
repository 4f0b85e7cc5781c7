#include "detect/centernet.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

namespace mocap::detect {
namespace {

// σ(class logits) and the box sides ×16: the graph's tower_0/keypoints and tower_0/wh, whose
// Identity nodes cv::dnn drops, so the nodes before them.
const std::array<std::string, 2> kHeads = {"tower_0/Sigmoid", "tower_0/mul"};
constexpr int kStride = 4;

}  // namespace

float iou(const Box2D& a, const Box2D& b) {
  const float x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
  const float x1 = std::min(a.x + a.width, b.x + b.width);
  const float y1 = std::min(a.y + a.height, b.y + b.height);
  const float inter = std::max(0.0f, x1 - x0) * std::max(0.0f, y1 - y0);
  const float uni = a.width * a.height + b.width * b.height - inter;
  return uni > 0 ? inter / uni : 0.0f;
}

std::vector<Detection> decode_centernet(const Tensor& heatmap, const Tensor& sides, int class_id,
                                        float min_score, int max_count) {
  const int h = heatmap.height, w = heatmap.width;
  if (heatmap.batch < 1 || sides.batch < 1 || sides.channels != 4 || sides.height != h ||
      sides.width != w || class_id < 0 || class_id >= heatmap.channels ||
      heatmap.values.size() < heatmap.plane() * heatmap.channels ||
      sides.values.size() < sides.plane() * 4)
    throw std::invalid_argument("CenterNet heads of inconsistent shapes");
  const float* heat = heatmap.at(0, class_id);
  std::vector<Detection> found;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float v = heat[y * w + x];
      if (v < min_score) continue;
      // A peak equals the 3 × 3 maximum around it (SAME padding: the border has fewer cells).
      bool peak = true;
      for (int yy = std::max(0, y - 1); peak && yy <= std::min(h - 1, y + 1); ++yy)
        for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx)
          if (heat[yy * w + xx] > v) peak = false;
      if (!peak) continue;
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const float cx = static_cast<float>(kStride * x), cy = static_cast<float>(kStride * y);
      const float left = sides.at(0, 0)[i], top = sides.at(0, 1)[i];
      const float right = sides.at(0, 2)[i], bottom = sides.at(0, 3)[i];
      found.push_back({{cx - left, cy - top, left + right, top + bottom}, v});
    }
  }
  // Score order; equal scores keep row-major order (TopKV2 prefers the lower index).
  std::stable_sort(found.begin(), found.end(),
                   [](const Detection& a, const Detection& b) { return a.score > b.score; });
  if (max_count >= 0 && found.size() > static_cast<std::size_t>(max_count))
    found.resize(static_cast<std::size_t>(max_count));
  return found;
}

std::vector<Detection> suppress_overlaps(std::vector<Detection> detections, float max_iou) {
  std::stable_sort(detections.begin(), detections.end(),
                   [](const Detection& a, const Detection& b) { return a.score > b.score; });
  std::vector<Detection> kept;
  for (const Detection& d : detections) {
    const bool overlaps = std::any_of(
        kept.begin(), kept.end(), [&](const Detection& k) { return iou(k.box, d.box) > max_iou; });
    if (!overlaps) kept.push_back(d);
  }
  return kept;
}

CenternetNetwork::CenternetNetwork(const std::filesystem::path& model_json)
    : graph_(model_json, kHeads) {}

std::vector<Tensor> CenternetNetwork::run(const Tensor& image) {
  if (image.batch != 1 || image.channels != 3 || image.height != kCenternetInput ||
      image.width != kCenternetInput)
    throw std::invalid_argument("CenterNet takes one 3 x 512 x 512 image");
  std::vector<Tensor> heads = graph_.run(image);
  const int grid = kCenternetInput / kStride;
  if (heads.size() != 2 || heads[0].height != grid || heads[0].width != grid ||
      heads[1].channels != 4)
    throw std::runtime_error(
        "CenterNet: heads of an unexpected shape (is the model file the "
        "right one?)");
  return heads;
}

}  // namespace mocap::detect
