#include "detect/singlepose.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace mocap::detect {
namespace {

const std::array<std::string, 4> kHeads = {"StatefulPartitionedCall/center_0/conv2d_4/BiasAdd",
                                           "StatefulPartitionedCall/kpt_heatmap_0/conv2d_5/BiasAdd",
                                           "StatefulPartitionedCall/kpt_regress_0/conv2d_6/BiasAdd",
                                           "StatefulPartitionedCall/kpt_offset_0/conv2d_7/BiasAdd"};
// The graph's input goes int32 -> Cast -> unstack -> ExpandDims -> Squeeze -> ExpandDims (batch 1
// juggling cv::dnn has no layers for) -> (x - [0,0,0]) · [1/127.5]×3 - 1, whose per-channel
// [1,1,1,3] constants OpenCV 4.6's Sub and Mul cannot take. The batch is fed after them, and the
// normalisation done here with the model's own (float16) constants.
const std::string kInputNode = "StatefulPartitionedCall/sub_1";
constexpr float kInputScale = 0.007843018f;  // StatefulPartitionedCall/truediv
// Added to the distances before dividing (StatefulPartitionedCall/add_5/y, float16 1.8).
constexpr float kDistanceBias = 1.7998047f;

float sigmoid(float v) { return 1.0f / (1.0f + std::exp(-v)); }

// x rounded to the nearest float16 value, as the model stores its constants (normal range only).
float round_to_half(float x) {
  if (x == 0.0f) return x;
  int exponent = 0;
  std::frexp(x, &exponent);  // x = m · 2^exponent, 0.5 <= |m| < 1
  const float step = std::ldexp(1.0f, exponent - 11);
  return std::nearbyint(x / step) * step;
}

void check_heads(const Tensor& center, const Tensor& heatmap, const Tensor& regress,
                 const Tensor& offset, int n) {
  const int h = center.height, w = center.width;
  const auto fits = [&](const Tensor& t, int channels) {
    return t.channels == channels && t.height == h && t.width == w && t.batch > n &&
           t.values.size() == static_cast<std::size_t>(t.batch) * channels * h * w;
  };
  if (h <= 0 || w <= 0 || n < 0 || !fits(center, 1) || !fits(heatmap, kMovenetKeypoints) ||
      !fits(regress, 2 * kMovenetKeypoints) || !fits(offset, 2 * kMovenetKeypoints))
    throw std::invalid_argument("MoveNet single-pose heads of inconsistent shapes");
}

}  // namespace

std::string_view model_name(SinglePoseModel model) {
  return model == SinglePoseModel::lightning ? "movenet-lightning" : "movenet-thunder";
}

int input_size(SinglePoseModel model) { return model == SinglePoseModel::lightning ? 192 : 256; }

SinglePoseKeypoints decode_singlepose(const Tensor& center, const Tensor& heatmap,
                                      const Tensor& regress, const Tensor& offset, int n) {
  check_heads(center, heatmap, regress, offset, n);
  const int h = center.height, w = center.width;
  const std::size_t cells = center.plane();

  const float* c = center.at(n, 0);
  std::size_t best = 0;
  float best_value = -1.0f;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float dy = static_cast<float>(y) - static_cast<float>(h) / 2;
      const float dx = static_cast<float>(x) - static_cast<float>(w) / 2;
      const float weight = round_to_half(1.0f / (std::sqrt(dy * dy + dx * dx) + 1.8f));
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const float v = sigmoid(c[i]) * weight;
      if (v > best_value) best_value = v, best = i;
    }
  }
  const int cy = static_cast<int>(best / w), cx = static_cast<int>(best % w);
  const float scale_y = round_to_half(1.0f / static_cast<float>(h));
  const float scale_x = round_to_half(1.0f / static_cast<float>(w));

  SinglePoseKeypoints out{};
  for (int k = 0; k < kMovenetKeypoints; ++k) {
    const float ry = static_cast<float>(cy) + regress.at(n, 2 * k)[best];
    const float rx = static_cast<float>(cx) + regress.at(n, 2 * k + 1)[best];
    const float* heat = heatmap.at(n, k);
    std::size_t top = 0;
    float top_value = -1.0f;
    for (std::size_t i = 0; i < cells; ++i) {
      const float dy = static_cast<float>(i / w) - ry, dx = static_cast<float>(i % w) - rx;
      const float v = sigmoid(heat[i]) / (std::sqrt(dy * dy + dx * dx) + kDistanceBias);
      if (v > top_value) top_value = v, top = i;
    }
    const float y = static_cast<float>(top / w) + offset.at(n, 2 * k)[top];
    const float x = static_cast<float>(top % w) + offset.at(n, 2 * k + 1)[top];
    out[k] = {y * scale_y, x * scale_x, sigmoid(heat[top])};
  }
  return out;
}

SinglePoseNetwork::SinglePoseNetwork(SinglePoseModel model, const std::filesystem::path& model_json)
    : model_(model), graph_(model_json, kHeads, kInputNode) {}

std::vector<Tensor> SinglePoseNetwork::run_heads(const Tensor& crops) {
  const int size = input_size();
  if (crops.channels != 3 || crops.height != size || crops.width != size || crops.batch < 1)
    throw std::invalid_argument(std::string(model_name(model_)) + " takes crops of 3 x " +
                                std::to_string(size) + " x " + std::to_string(size));
  normalised_.batch = crops.batch;
  normalised_.channels = crops.channels;
  normalised_.height = crops.height;
  normalised_.width = crops.width;
  normalised_.values.resize(crops.values.size());
  for (std::size_t i = 0; i < crops.values.size(); ++i)
    normalised_.values[i] = crops.values[i] * kInputScale - 1.0f;
  std::vector<Tensor> heads = graph_.run(normalised_);
  const int grid = size / 4;
  for (const Tensor& t : heads) {
    if (t.height != grid || t.width != grid || t.batch != crops.batch)
      throw std::runtime_error(std::string(model_name(model_)) + ": heads of " +
                               std::to_string(t.height) + " x " + std::to_string(t.width) +
                               " cells, expected " + std::to_string(grid) +
                               " (is the model file the right one?)");
  }
  return heads;
}

std::vector<SinglePoseKeypoints> SinglePoseNetwork::run(const Tensor& crops) {
  const std::vector<Tensor> heads = run_heads(crops);
  std::vector<SinglePoseKeypoints> out;
  out.reserve(static_cast<std::size_t>(crops.batch));
  for (int n = 0; n < crops.batch; ++n)
    out.push_back(decode_singlepose(heads[0], heads[1], heads[2], heads[3], n));
  return out;
}

}  // namespace mocap::detect
