#pragma once
// One TF.js graph model run by OpenCV's cv::dnn: "feed this float tensor, give me these outputs".
// The detectors' network classes (single-pose MoveNet, CenterNet) hold one and know nothing of
// cv::dnn, so another runtime behind the same two calls is a change in this file only.
//
// Tensors are NCHW float32, contiguous: value (n, c, y, x) at ((n * C + c) * H + y) * W + x.

#include <cstddef>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace mocap::detect {

struct Tensor {
  int batch = 0, channels = 0, height = 0, width = 0;
  std::vector<float> values;

  std::size_t plane() const { return static_cast<std::size_t>(height) * width; }
  // Where (n, c, 0, 0) starts.
  const float* at(int n, int c) const {
    return values.data() + (static_cast<std::size_t>(n) * channels + c) * plane();
  }
};

class DnnGraph {
 public:
  // Loads `model_json` cut at `outputs` (node names), fed at `input_node` (empty: the graph's
  // own placeholder). Throws std::runtime_error naming the file and the command that fetches it
  // when the model cannot be read, converted or imported.
  DnnGraph(const std::filesystem::path& model_json, std::span<const std::string> outputs,
           const std::string& input_node = {});
  ~DnnGraph();
  DnnGraph(DnnGraph&&) noexcept;
  DnnGraph& operator=(DnnGraph&&) noexcept;

  // The outputs, in the order given to the constructor, for one NCHW input.
  std::vector<Tensor> run(const Tensor& input);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::detect
