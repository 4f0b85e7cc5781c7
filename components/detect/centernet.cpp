#include "detect/centernet.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include "detect/model_files.hpp"
#include "detect/tfjs_model.hpp"

namespace mocap::detect {
namespace {

// σ(class logits) and the box sides ×16: the graph's tower_0/keypoints and tower_0/wh, whose
// Identity nodes cv::dnn drops, so the nodes before them (the same for both runtimes).
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

std::vector<Detection> decode_centernet(const GraphTensor& heatmap, const GraphTensor& sides,
                                        int class_id, float min_score, int max_count) {
  if (heatmap.shape.size() != 4 || sides.shape.size() != 4)
    throw std::invalid_argument("CenterNet heads of inconsistent shapes");
  const int h = static_cast<int>(heatmap.shape[1]), w = static_cast<int>(heatmap.shape[2]);
  const int classes = static_cast<int>(heatmap.shape[3]);
  if (heatmap.shape[0] < 1 || sides.shape[0] < 1 || sides.shape[1] != h || sides.shape[2] != w ||
      sides.shape[3] != 4 || h <= 0 || w <= 0 || class_id < 0 || class_id >= classes ||
      heatmap.values.size() != heatmap.size() || sides.values.size() != sides.size())
    throw std::invalid_argument("CenterNet heads of inconsistent shapes");
  // Image 0, NHWC: class c of cell i at i · classes + c, side s at i · 4 + s.
  const auto heat_at = [&](std::size_t i) {
    return heatmap
        .values[i * static_cast<std::size_t>(classes) + static_cast<std::size_t>(class_id)];
  };
  std::vector<Detection> found;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float v = heat_at(static_cast<std::size_t>(y) * w + x);
      if (v < min_score) continue;
      // A peak equals the 3 × 3 maximum around it (SAME padding: the border has fewer cells).
      bool peak = true;
      for (int yy = std::max(0, y - 1); peak && yy <= std::min(h - 1, y + 1); ++yy)
        for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx)
          if (heat_at(static_cast<std::size_t>(yy) * w + xx) > v) peak = false;
      if (!peak) continue;
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const float cx = static_cast<float>(kStride * x), cy = static_cast<float>(kStride * y);
      const float* side = sides.values.data() + i * 4;
      const float left = side[0], top = side[1], right = side[2], bottom = side[3];
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

CenternetNetwork::CenternetNetwork(const std::filesystem::path& model_json,
                                   const RunnerOptions& options)
    : runner_(make_graph_runner(model_json, kHeads, options)) {}

CenternetNetwork::CenternetNetwork(const std::filesystem::path& model_json, int height, int width,
                                   const RunnerOptions& options)
    : height_(height), width_(width) {
  constexpr int kGraphStride = 32;  // MobileNetV3's deepest feature map: 1/32 of the input
  if (height < kGraphStride || width < kGraphStride || height % kGraphStride != 0 ||
      width % kGraphStride != 0)
    throw std::invalid_argument("CenterNet's input sides must be multiples of 32, got " +
                                std::to_string(height) + " x " + std::to_string(width));
  if (height == kCenternetInput && width == kCenternetInput) {
    runner_ = make_graph_runner(model_json, kHeads, options);
    return;
  }
  try {
    runner_ = make_graph_runner(std::make_shared<const TfjsModel>(tfjs_with_input_size(
                                    read_tfjs_model(model_json), height, width)),
                                kHeads, options);
  } catch (const ModelError& e) {
    throw ModelError(std::string(e.what()) + "; if the file is damaged or not this model, " +
                     kFetchModelsHint);
  }
}

const std::vector<GraphTensor>& CenternetNetwork::run(const GraphTensor& image) {
  if (image.shape != std::vector<std::int64_t>{1, height_, width_, 3} ||
      image.values.size() != image.size())
    throw std::invalid_argument("CenterNet takes one " + std::to_string(height_) + " x " +
                                std::to_string(width_) + " x 3 image");
  runner_->run({image.shape, image.values}, heads_);
  if (heads_.size() != 2 || heads_[0].shape.size() != 4 || heads_[1].shape.size() != 4 ||
      heads_[0].shape[1] != height_ / kStride || heads_[0].shape[2] != width_ / kStride ||
      heads_[1].shape[3] != 4)
    throw std::runtime_error(
        "CenterNet: heads of an unexpected shape (is the model file the right one?)");
  return heads_;
}

}  // namespace mocap::detect
