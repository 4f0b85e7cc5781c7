#pragma once
// MoveNet MultiPose's post-processing in C++: the six CenterNet head tensors of the CNN become the
// model's own [6, 56] output (the arithmetic of the graph part cv::dnn cannot import; see
// ../shared/docs/models/movenet-multipose.md §7), and the rows that pass the thresholds become
// people in image pixels.

#include <array>
#include <vector>

#include "core/messages.hpp"

namespace mocap::detect {

inline constexpr int kMovenetKeypoints = 17;  // COCO-17 order
inline constexpr int kMovenetInstances = 6;
inline constexpr int kMovenetRowSize = 3 * kMovenetKeypoints + 5;  // 56

// The heads on the stride-4 grid (height × width cells), channels last: value (c, y, x) at
// [(y * width + x) * channels + c], as TensorFlow gives them (NHWC without the batch).
struct MovenetHeads {
  int height = 0, width = 0;
  std::vector<float> center;      // 1 channel: person-centre logit
  std::vector<float> box_scale;   // 2: box height, width in cells
  std::vector<float> box_offset;  // 2: centre sub-cell offset dy, dx
  std::vector<float> heatmap;     // 17: keypoint logits
  std::vector<float> regress;     // 34: joint displacement from the centre cell, dy, dx
  std::vector<float> offset;      // 34: joint sub-cell offset, dy, dx
};

// One row of the model's output: 17 × (y, x, score), then ymin, xmin, ymax, xmax, score; y and x
// normalised to the fed tensor. Rows come in centre-score order, not final-score order.
using MovenetRow = std::array<float, kMovenetRowSize>;

// Throws std::invalid_argument when the head sizes do not match height × width × channels.
std::array<MovenetRow, kMovenetInstances> decode_movenet(const MovenetHeads& heads);

// Where the fed tensor came from: image = (tensor - pad) / scale, in pixels (x and y scales
// differ slightly when the short side was rounded to whole pixels).
struct TensorMapping {
  int tensor_width = 0, tensor_height = 0;
  float scale_x = 1, scale_y = 1;
  float pad_left = 0, pad_top = 0;
};

struct MovenetThresholds {
  float min_person_score = 0.25f;   // tfjs-models' default minPoseScore
  float min_keypoint_score = 0.3f;  // keypoints below it are missing (NaN, confidence 0)
};

struct MovenetPerson {
  float score = 0;
  Box2D box;  // image pixels
  std::array<Keypoint2D, kMovenetKeypoints> keypoints{};
};

// The rows scoring at least min_person_score, best first, mapped to image pixels.
std::vector<MovenetPerson> select_people(const std::array<MovenetRow, kMovenetInstances>& rows,
                                         const TensorMapping& mapping,
                                         const MovenetThresholds& thresholds);

}  // namespace mocap::detect
