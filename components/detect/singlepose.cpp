#include "detect/singlepose.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mocap::detect {
namespace {

const std::vector<std::string> kHeads = {"StatefulPartitionedCall/center_0/conv2d_4/BiasAdd",
                                         "StatefulPartitionedCall/kpt_heatmap_0/conv2d_5/BiasAdd",
                                         "StatefulPartitionedCall/kpt_regress_0/conv2d_6/BiasAdd",
                                         "StatefulPartitionedCall/kpt_offset_0/conv2d_7/BiasAdd"};
// The graph's input goes int32 -> Cast -> unstack -> ExpandDims -> Squeeze -> ExpandDims (batch 1
// juggling) -> x - [0, 0, 0] -> the normalisation. It is fed at that subtraction (the same values,
// RGB 0..255), so a batch of crops runs in one pass and the model normalises them itself; at
// `stack`, cv::dnn 4.6 fails on a batch of two in the subtraction (runtime_golden_test).
const std::string kInputNode = "StatefulPartitionedCall/sub";
// BlazePose's landmark model is cut before its reshapes to [N, 195] and [N, 1] (cv::dnn's TF
// importer does not take them) and before the heatmap and segmentation branches it does not need.
const std::vector<std::string> kBlazePoseHeads = {
    "StatefulPartitionedCall/model/convld_3d/BiasAdd",
    "StatefulPartitionedCall/model/activation_poseflag/Sigmoid"};
constexpr int kBlazePoseValues = 5;  // x, y, z (pixels of the crop), visibility, presence (logits)

struct ModelInfo {
  SinglePoseModel model;
  std::string_view folder, short_name;
  int input_size;
};
constexpr std::array<ModelInfo, 5> kModels = {{
    {SinglePoseModel::lightning, "movenet-lightning", "lightning", 192},
    {SinglePoseModel::thunder, "movenet-thunder", "thunder", 256},
    {SinglePoseModel::blazepose_lite, "blazepose-lite", "blazepose-lite", 256},
    {SinglePoseModel::blazepose_full, "blazepose-full", "blazepose-full", 256},
    {SinglePoseModel::blazepose_heavy, "blazepose-heavy", "blazepose-heavy", 256},
}};

const ModelInfo& info(SinglePoseModel model) {
  for (const ModelInfo& m : kModels)
    if (m.model == model) return m;
  throw std::invalid_argument("unknown single-pose model");
}

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

void check_heads(const GraphTensor& center, const GraphTensor& heatmap, const GraphTensor& regress,
                 const GraphTensor& offset, int n) {
  if (center.shape.size() != 4)
    throw std::invalid_argument("MoveNet single-pose heads of inconsistent shapes");
  const std::int64_t batch = center.shape[0], h = center.shape[1], w = center.shape[2];
  const auto fits = [&](const GraphTensor& t, int channels) {
    return t.shape == std::vector<std::int64_t>{batch, h, w, channels} &&
           t.values.size() == t.size();
  };
  if (h <= 0 || w <= 0 || n < 0 || n >= batch || !fits(center, 1) ||
      !fits(heatmap, kMovenetKeypoints) || !fits(regress, 2 * kMovenetKeypoints) ||
      !fits(offset, 2 * kMovenetKeypoints))
    throw std::invalid_argument("MoveNet single-pose heads of inconsistent shapes");
}

// Channel c of cell i (row-major y · w + x) of crop n, in an NHWC head.
float at(const GraphTensor& t, int n, std::size_t i, int c) {
  const auto cells = static_cast<std::size_t>(t.shape[1] * t.shape[2]);
  const auto channels = static_cast<std::size_t>(t.shape[3]);
  return t
      .values[(static_cast<std::size_t>(n) * cells + i) * channels + static_cast<std::size_t>(c)];
}

}  // namespace

std::string_view model_name(SinglePoseModel model) { return info(model).folder; }

std::string_view short_name(SinglePoseModel model) { return info(model).short_name; }

std::string_view pose_model_names() {
  return "lightning|thunder|blazepose-lite|blazepose-full|blazepose-heavy";
}

SinglePoseModel parse_pose_model(std::string_view name) {
  for (const ModelInfo& m : kModels)
    if (m.short_name == name) return m.model;
  throw std::invalid_argument("pose_model must be one of " + std::string(pose_model_names()) +
                              ", got '" + std::string(name) + "'");
}

bool is_blazepose(SinglePoseModel model) {
  return model != SinglePoseModel::lightning && model != SinglePoseModel::thunder;
}

int input_size(SinglePoseModel model) { return info(model).input_size; }

SinglePose decode_blazepose(const GraphTensor& landmarks, const GraphTensor& flag, int size,
                            int n) {
  constexpr std::size_t kPerCrop = std::size_t{kBlazePoseLandmarks} * kBlazePoseValues;
  const std::int64_t batch = landmarks.shape.empty() ? 0 : landmarks.shape[0];
  if (size <= 0 || n < 0 || n >= batch || landmarks.values.size() != landmarks.size() ||
      landmarks.size() != static_cast<std::size_t>(batch) * kPerCrop || flag.shape.empty() ||
      flag.shape[0] != batch || flag.values.size() != flag.size() ||
      flag.size() != static_cast<std::size_t>(batch))
    throw std::invalid_argument("BlazePose outputs of inconsistent shapes");
  const float* v = landmarks.values.data() + static_cast<std::size_t>(n) * kPerCrop;
  SinglePose out;
  const float scale = 1.0f / static_cast<float>(size);
  for (int k = 0; k < kMovenetKeypoints; ++k) {
    const float* l = v + static_cast<std::size_t>(kBlazePoseToCoco[k]) * kBlazePoseValues;
    out.keypoints[k] = {l[1] * scale, l[0] * scale, sigmoid(l[3])};
  }
  for (int k = 0; k < kBlazePoseBody; ++k) {
    const float* l = v + static_cast<std::size_t>(k) * kBlazePoseValues;
    out.body[static_cast<std::size_t>(k)] = {l[1] * scale, l[0] * scale, sigmoid(l[4])};
  }
  out.body_landmarks = kBlazePoseBody;
  out.presence = flag.values[static_cast<std::size_t>(n)];
  return out;
}

SinglePoseKeypoints decode_singlepose(const GraphTensor& center, const GraphTensor& heatmap,
                                      const GraphTensor& regress, const GraphTensor& offset,
                                      int n) {
  check_heads(center, heatmap, regress, offset, n);
  const int h = static_cast<int>(center.shape[1]), w = static_cast<int>(center.shape[2]);
  const std::size_t cells = static_cast<std::size_t>(h) * w;

  std::size_t best = 0;
  float best_value = -1.0f;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float dy = static_cast<float>(y) - static_cast<float>(h) / 2;
      const float dx = static_cast<float>(x) - static_cast<float>(w) / 2;
      const float weight = round_to_half(1.0f / (std::sqrt(dy * dy + dx * dx) + 1.8f));
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const float v = sigmoid(at(center, n, i, 0)) * weight;
      if (v > best_value) best_value = v, best = i;
    }
  }
  const int cy = static_cast<int>(best / w), cx = static_cast<int>(best % w);
  const float scale_y = round_to_half(1.0f / static_cast<float>(h));
  const float scale_x = round_to_half(1.0f / static_cast<float>(w));

  SinglePoseKeypoints out{};
  for (int k = 0; k < kMovenetKeypoints; ++k) {
    const float ry = static_cast<float>(cy) + at(regress, n, best, 2 * k);
    const float rx = static_cast<float>(cx) + at(regress, n, best, 2 * k + 1);
    std::size_t top = 0;
    float top_value = -1.0f;
    for (std::size_t i = 0; i < cells; ++i) {
      const float dy = static_cast<float>(i / w) - ry, dx = static_cast<float>(i % w) - rx;
      const float v =
          sigmoid(at(heatmap, n, i, k)) / (std::sqrt(dy * dy + dx * dx) + kDistanceBias);
      if (v > top_value) top_value = v, top = i;
    }
    const float y = static_cast<float>(top / w) + at(offset, n, top, 2 * k);
    const float x = static_cast<float>(top % w) + at(offset, n, top, 2 * k + 1);
    out[k] = {y * scale_y, x * scale_x, sigmoid(at(heatmap, n, top, k))};
  }
  return out;
}

namespace {

// MoveNet is fed after its batch-of-one reshuffles, BlazePose at its placeholder.
RunnerOptions runner_options(SinglePoseModel model, RunnerOptions options) {
  options.input_node = is_blazepose(model) ? "" : kInputNode;
  return options;
}

}  // namespace

SinglePoseNetwork::SinglePoseNetwork(SinglePoseModel model, const std::filesystem::path& model_json,
                                     const RunnerOptions& options)
    : model_(model),
      runner_(make_graph_runner(model_json, is_blazepose(model) ? kBlazePoseHeads : kHeads,
                                runner_options(model, options))) {}

const std::vector<GraphTensor>& SinglePoseNetwork::run_heads(const GraphTensor& crops) {
  const int size = input_size();
  if (crops.shape.size() != 4 || crops.shape[0] < 1 || crops.shape[1] != size ||
      crops.shape[2] != size || crops.shape[3] != 3 || crops.values.size() != crops.size())
    throw std::invalid_argument(std::string(model_name(model_)) + " takes crops of " +
                                std::to_string(size) + " x " + std::to_string(size) + " x 3");
  if (is_blazepose(model_)) {
    scaled_.shape = crops.shape;
    scaled_.values.resize(crops.values.size());
    std::transform(crops.values.begin(), crops.values.end(), scaled_.values.begin(),
                   [](float v) { return v * (1.0f / 255.0f); });
    runner_->run({scaled_.shape, scaled_.values}, heads_);
    return heads_;
  }
  runner_->run({crops.shape, crops.values}, heads_);
  const int grid = size / 4;
  for (const GraphTensor& t : heads_) {
    if (t.shape.size() != 4 || t.shape[0] != crops.shape[0] || t.shape[1] != grid ||
        t.shape[2] != grid)
      throw std::runtime_error(std::string(model_name(model_)) +
                               ": heads of an unexpected shape, expected " + std::to_string(grid) +
                               " x " + std::to_string(grid) +
                               " cells (is the model file the "
                               "right one?)");
  }
  return heads_;
}

std::vector<SinglePose> SinglePoseNetwork::run(const GraphTensor& crops, int largest_pass) {
  const int batch = crops.shape.empty() ? 0 : static_cast<int>(crops.shape[0]);
  std::vector<SinglePose> out(static_cast<std::size_t>(std::max(batch, 0)));
  run(crops, 0, batch, out, largest_pass);
  return out;
}

void SinglePoseNetwork::run(const GraphTensor& crops, int first, int count,
                            std::span<SinglePose> out, int largest_pass) {
  if (largest_pass < 1 || largest_pass > kMaxPass || (largest_pass & (largest_pass - 1)) != 0)
    throw std::invalid_argument(std::string(model_name(model_)) +
                                ": the largest pass must be 1, 2, 4 or 8 crops, not " +
                                std::to_string(largest_pass));
  if (crops.shape.size() != 4 || crops.values.size() != crops.size())
    throw std::invalid_argument(std::string(model_name(model_)) + ": malformed crop batch");
  const int batch = static_cast<int>(crops.shape[0]);
  if (first < 0 || count < 0 || first + count > batch ||
      out.size() < static_cast<std::size_t>(count))
    throw std::invalid_argument(std::string(model_name(model_)) + ": crops " +
                                std::to_string(first) + " + " + std::to_string(count) +
                                " outside the batch of " + std::to_string(batch));
  const std::size_t per_crop = batch > 0 ? crops.size() / static_cast<std::size_t>(batch) : 0;
  for (int done = 0; done < count;) {
    int pass = largest_pass;
    while (pass > count - done) pass /= 2;
    pass_.shape = crops.shape;
    pass_.shape[0] = pass;
    const auto begin =
        crops.values.begin() + static_cast<std::ptrdiff_t>((first + done) * per_crop);
    pass_.values.assign(begin, begin + static_cast<std::ptrdiff_t>(pass * per_crop));
    const std::vector<GraphTensor>& heads = run_heads(pass_);
    for (int n = 0; n < pass; ++n) {
      SinglePose& o = out[static_cast<std::size_t>(done + n)];
      if (is_blazepose(model_))
        o = decode_blazepose(heads[0], heads[1], input_size(), n);
      else
        o = {decode_singlepose(heads[0], heads[1], heads[2], heads[3], n), kNoPresence, {}, 0};
    }
    done += pass;
  }
}

}  // namespace mocap::detect
