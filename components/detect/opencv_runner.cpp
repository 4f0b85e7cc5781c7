// GraphRunner on OpenCV's cv::dnn: the TF.js model written as a TensorFlow GraphDef
// (tfjs_graph.hpp) and imported by cv::dnn::readNetFromTensorflow. cv::dnn computes NCHW: a 4-D
// input in TensorFlow's layout [a, b, c, d] is fed as the blob [a, d, b, c], and 4-D outputs come
// back from that order (the TF importer's convention for NHWC graphs).

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include "detect/runner_backends.hpp"
#include "detect/tfjs_graph.hpp"

namespace mocap::detect {
namespace {

// The cv::dnn layer that computes node `name`: a Conv2D + BiasAdd pair is named after the Conv2D
// node, which is what a split fused convolution without activation ends in.
std::string layer_name(const TfjsModel& model, const std::string& output) {
  if (tfjs_output_index(output) != 0)
    fail_model(model.file, "output '" + output + "': the cv::dnn runtime gives first outputs only");
  const std::string name = tfjs_base_name(output);
  for (const TfjsNode& n : model.nodes) {
    if (n.name != name) continue;
    const bool split = n.op == "_FusedConv2D" || n.op == "FusedDepthwiseConv2dNative";
    return split && tfjs_fused_ops(n).size() == 1 ? fused_conv_layer_name(name) : name;
  }
  fail_model(model.file, "the graph has no node '" + name + "'");
}

// NHWC-ordered [a, b, c, d] values to the NCHW blob [a, d, b, c], and back.
void to_blob(const GraphTensorView& input, cv::Mat& blob) {
  const auto& s = input.shape;
  const int dims[] = {static_cast<int>(s[0]), static_cast<int>(s[3]), static_cast<int>(s[1]),
                      static_cast<int>(s[2])};
  blob.create(4, dims, CV_32F);
  float* out = blob.ptr<float>();
  const std::size_t plane = static_cast<std::size_t>(s[1] * s[2]);
  const auto channels = static_cast<std::size_t>(s[3]);
  for (std::int64_t n = 0; n < s[0]; ++n) {
    const float* in = input.values.data() + static_cast<std::size_t>(n) * plane * channels;
    float* o = out + static_cast<std::size_t>(n) * plane * channels;
    for (std::size_t i = 0; i < plane; ++i)
      for (std::size_t c = 0; c < channels; ++c) o[c * plane + i] = in[i * channels + c];
  }
}

void from_blob(const cv::Mat& blob, GraphTensor& out) {
  const cv::Mat m = blob.isContinuous() ? blob : blob.clone();
  const float* in = m.ptr<float>();
  if (m.dims != 4) {
    out.shape.assign(m.size.p, m.size.p + m.dims);
    out.values.assign(in, in + m.total());
    return;
  }
  const std::int64_t n = m.size[0], c = m.size[1], h = m.size[2], w = m.size[3];
  out.shape = {n, h, w, c};
  out.values.resize(m.total());
  const auto plane = static_cast<std::size_t>(h * w);
  const auto channels = static_cast<std::size_t>(c);
  for (std::int64_t b = 0; b < n; ++b) {
    const float* src = in + static_cast<std::size_t>(b) * plane * channels;
    float* dst = out.values.data() + static_cast<std::size_t>(b) * plane * channels;
    for (std::size_t ch = 0; ch < channels; ++ch)
      for (std::size_t i = 0; i < plane; ++i) dst[i * channels + ch] = src[ch * plane + i];
  }
}

class OpenCvRunner : public GraphRunner {
 public:
  OpenCvRunner(const TfjsModel& model, std::span<const std::string> outputs,
               const RunnerOptions& options)
      : file_(model.file) {
    const std::string graph = tfjs_to_graphdef(model, outputs, options.input_node);
    try {
      net_ = cv::dnn::readNetFromTensorflow(graph.data(), graph.size());
    } catch (const cv::Exception& e) {
      fail_model(model.file, std::string("cv::dnn could not import it: ") + e.what());
    }
    for (const std::string& output : outputs) names_.push_back(layer_name(model, output));
    if (options.threads > 0) cv::setNumThreads(options.threads);
  }

  void run(const GraphTensorView& input, std::vector<GraphTensor>& outputs) override {
    std::size_t size = 1;
    for (const std::int64_t d : input.shape) {
      if (d <= 0) throw std::invalid_argument("network input with an empty dimension");
      size *= static_cast<std::size_t>(d);
    }
    if (input.shape.size() != 4 || size != input.values.size())
      throw std::invalid_argument("network input must be 4-D with as many values as its shape");
    to_blob(input, blob_);
    try {
      net_.setInput(blob_);
      net_.forward(outs_, names_);
    } catch (const cv::Exception& e) {
      throw std::runtime_error("cv::dnn failed on " + file_.string() + ": " + e.what());
    }
    outputs.resize(outs_.size());
    for (std::size_t i = 0; i < outs_.size(); ++i) from_blob(outs_[i], outputs[i]);
  }

  Backend backend() const override { return Backend::opencv; }

 private:
  std::filesystem::path file_;
  cv::dnn::Net net_;
  std::vector<cv::String> names_;
  cv::Mat blob_;
  std::vector<cv::Mat> outs_;
};

}  // namespace

std::unique_ptr<GraphRunner> make_opencv_runner(std::shared_ptr<const TfjsModel> model,
                                                std::span<const std::string> outputs,
                                                const RunnerOptions& options) {
  return std::make_unique<OpenCvRunner>(*model, outputs, options);
}

}  // namespace mocap::detect
