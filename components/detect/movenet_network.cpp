#include "detect/movenet_network.hpp"

#include <array>
#include <stdexcept>
#include <string>

namespace mocap::detect {
namespace {

// The six head nodes of the TF.js graph, in MovenetHeads' order; the graph's own
// post-processing after them is replaced by decode_movenet.
const std::array<std::string, 6> kHeadNodes = {
    "StatefulPartitionedCall/center_0/conv2d_4/BiasAdd",
    "StatefulPartitionedCall/box_scale_0/conv2d_5/BiasAdd",
    "StatefulPartitionedCall/box_offset_0/conv2d_6/BiasAdd",
    "StatefulPartitionedCall/kpt_heatmap_0/conv2d_7/BiasAdd",
    "StatefulPartitionedCall/kpt_regress_0/conv2d_8/BiasAdd",
    "StatefulPartitionedCall/kpt_offset_0/conv2d_9/BiasAdd"};
constexpr std::array<int, 6> kHeadChannels = {
    1, 2, 2, kMovenetKeypoints, 2 * kMovenetKeypoints, 2 * kMovenetKeypoints};
constexpr int kStride = 4, kSizeMultiple = 32;

// RGB values 0..255 as float NHWC (the graph normalises them itself).
void to_rgb_floats(const ImageBuffer& image, std::vector<float>& out) {
  const int w = image.width(), h = image.height();
  out.resize(static_cast<std::size_t>(w) * h * 3);
  const bool bgr = image.format() == PixelFormat::bgr8;
  float* o = out.data();
  for (int y = 0; y < h; ++y) {
    const auto* row = reinterpret_cast<const unsigned char*>(
        image.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(image.stride()));
    for (int x = 0; x < w; ++x, row += 3, o += 3) {
      o[0] = row[bgr ? 2 : 0];
      o[1] = row[1];
      o[2] = row[bgr ? 0 : 2];
    }
  }
}

}  // namespace

MovenetNetwork::MovenetNetwork(const std::filesystem::path& model_json,
                               const RunnerOptions& options)
    : runner_(make_graph_runner(model_json, kHeadNodes, options)) {}

MovenetNetwork::~MovenetNetwork() = default;
MovenetNetwork::MovenetNetwork(MovenetNetwork&&) noexcept = default;
MovenetNetwork& MovenetNetwork::operator=(MovenetNetwork&&) noexcept = default;

Backend MovenetNetwork::backend() const { return runner_->backend(); }

MovenetHeads MovenetNetwork::run(const ImageBuffer& tensor) {
  MovenetHeads heads;
  run(tensor, heads);
  return heads;
}

void MovenetNetwork::run(const ImageBuffer& tensor, MovenetHeads& heads) {
  const PixelFormat format = tensor.format();
  if (format != PixelFormat::rgb8 && format != PixelFormat::bgr8)
    throw std::invalid_argument("MoveNet input must be rgb8 or bgr8, got " +
                                std::string(name(format)));
  if (tensor.width() % kSizeMultiple || tensor.height() % kSizeMultiple || tensor.empty())
    throw std::invalid_argument("MoveNet input size " + std::to_string(tensor.width()) + "x" +
                                std::to_string(tensor.height()) + " is not a multiple of 32");
  to_rgb_floats(tensor, input_);
  const std::array<std::int64_t, 4> shape = {1, tensor.height(), tensor.width(), 3};
  runner_->run({shape, input_}, outputs_);

  heads.height = tensor.height() / kStride;
  heads.width = tensor.width() / kStride;
  const std::array<std::vector<float>*, 6> targets = {&heads.center,     &heads.box_scale,
                                                      &heads.box_offset, &heads.heatmap,
                                                      &heads.regress,    &heads.offset};
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const GraphTensor& out = outputs_[i];
    if (out.shape != std::vector<std::int64_t>{1, heads.height, heads.width, kHeadChannels[i]})
      throw std::runtime_error("MoveNet head " + kHeadNodes[i] + " has an unexpected shape");
    targets[i]->swap(outputs_[i].values);  // the runner refills its vector next time
  }
}

}  // namespace mocap::detect
