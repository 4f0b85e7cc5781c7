#include "detect/movenet_network.hpp"

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include "detect/tfjs_graph.hpp"

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

cv::dnn::Net load_net(const std::filesystem::path& model_json) {
  const std::string graph = tfjs_to_graphdef(model_json, kHeadNodes);
  try {
    return cv::dnn::readNetFromTensorflow(graph.data(), graph.size());
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cv::dnn could not import " + model_json.string() + ": " + e.what());
  }
}

std::vector<float> to_vector(const cv::Mat& blob) {
  const cv::Mat contiguous = blob.isContinuous() ? blob : blob.clone();
  const auto* p = contiguous.ptr<float>();
  return {p, p + contiguous.total()};
}

}  // namespace

struct MovenetNetwork::Impl {
  cv::dnn::Net net;
  std::vector<cv::String> outputs;
};

MovenetNetwork::MovenetNetwork(const std::filesystem::path& model_json)
    : impl_(std::make_unique<Impl>()) {
  impl_->net = load_net(model_json);
  for (const std::string& head : kHeadNodes) impl_->outputs.push_back(fused_conv_layer_name(head));
}

MovenetNetwork::~MovenetNetwork() = default;
MovenetNetwork::MovenetNetwork(MovenetNetwork&&) noexcept = default;
MovenetNetwork& MovenetNetwork::operator=(MovenetNetwork&&) noexcept = default;

MovenetHeads MovenetNetwork::run(const ImageBuffer& tensor) {
  const PixelFormat format = tensor.format();
  if (format != PixelFormat::rgb8 && format != PixelFormat::bgr8)
    throw std::invalid_argument("MoveNet input must be rgb8 or bgr8, got " +
                                std::string(name(format)));
  if (tensor.width() % kSizeMultiple || tensor.height() % kSizeMultiple || tensor.empty())
    throw std::invalid_argument("MoveNet input size " + std::to_string(tensor.width()) + "x" +
                                std::to_string(tensor.height()) + " is not a multiple of 32");
  const cv::Mat view(tensor.height(), tensor.width(), CV_8UC3,
                     const_cast<std::byte*>(tensor.data()),
                     static_cast<std::size_t>(tensor.stride()));
  // The graph normalises 0..255 itself; it wants RGB.
  const cv::Mat blob = cv::dnn::blobFromImage(view, 1.0, cv::Size(), cv::Scalar(),
                                              format == PixelFormat::bgr8, false, CV_32F);
  impl_->net.setInput(blob);
  std::vector<cv::Mat> outs;
  impl_->net.forward(outs, impl_->outputs);

  MovenetHeads heads;
  heads.height = tensor.height() / kStride;
  heads.width = tensor.width() / kStride;
  std::array<std::vector<float>*, 6> targets = {&heads.center,  &heads.box_scale, &heads.box_offset,
                                                &heads.heatmap, &heads.regress,   &heads.offset};
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const cv::Mat& out = outs[i];
    if (out.dims != 4 || out.size[1] != kHeadChannels[i] || out.size[2] != heads.height ||
        out.size[3] != heads.width)
      throw std::runtime_error("MoveNet head " + kHeadNodes[i] + " has an unexpected shape");
    *targets[i] = to_vector(out);
  }
  return heads;
}

}  // namespace mocap::detect
