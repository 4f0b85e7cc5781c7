#include "detect/dnn_graph.hpp"

#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include "detect/model_files.hpp"
#include "detect/tfjs_graph.hpp"

namespace mocap::detect {

struct DnnGraph::Impl {
  std::filesystem::path model;
  cv::dnn::Net net;
  std::vector<cv::String> layers;
};

namespace {

// cv::dnn folds a BiasAdd into the convolution before it and names the pair after the Conv2D
// node, which the loader calls fused_conv_layer_name() when it splits a _FusedConv2D; the TF.js
// converter names such a fused node after its BiasAdd. Every other node keeps its name.
std::vector<cv::String> layer_names(std::span<const std::string> outputs) {
  std::vector<cv::String> names;
  for (const std::string& output : outputs)
    names.push_back(output.ends_with("/BiasAdd") ? fused_conv_layer_name(output) : output);
  return names;
}

}  // namespace

DnnGraph::DnnGraph(const std::filesystem::path& model_json, std::span<const std::string> outputs,
                   const std::string& input_node)
    : impl_(std::make_unique<Impl>()) {
  impl_->model = model_json;
  std::string graph;
  try {
    graph = tfjs_to_graphdef(model_json, outputs, input_node);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string(e.what()) +
                             "; if the file is damaged or not this model, " + kFetchModelsHint);
  }
  try {
    impl_->net = cv::dnn::readNetFromTensorflow(graph.data(), graph.size());
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cv::dnn could not import " + model_json.string() + ": " + e.what());
  }
  impl_->layers = layer_names(outputs);
}

DnnGraph::~DnnGraph() = default;
DnnGraph::DnnGraph(DnnGraph&&) noexcept = default;
DnnGraph& DnnGraph::operator=(DnnGraph&&) noexcept = default;

std::vector<Tensor> DnnGraph::run(const Tensor& input) {
  const int shape[] = {input.batch, input.channels, input.height, input.width};
  const cv::Mat blob(4, shape, CV_32F, const_cast<float*>(input.values.data()));
  impl_->net.setInput(blob);
  std::vector<cv::Mat> outs;
  try {
    impl_->net.forward(outs, impl_->layers);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cv::dnn failed to run " + impl_->model.string() + ": " + e.what());
  }
  std::vector<Tensor> result;
  for (std::size_t i = 0; i < outs.size(); ++i) {
    const cv::Mat out = outs[i].isContinuous() ? outs[i] : outs[i].clone();
    if (out.dims != 4)
      throw std::runtime_error(impl_->model.string() + ": output " + impl_->layers[i] + " has " +
                               std::to_string(out.dims) + " dimensions, expected NCHW");
    Tensor t{out.size[0], out.size[1], out.size[2], out.size[3], {}};
    const float* p = out.ptr<float>();
    t.values.assign(p, p + out.total());
    result.push_back(std::move(t));
  }
  return result;
}

}  // namespace mocap::detect
