#pragma once
// "Run this network on this input tensor, give me these outputs": the one interface every
// detector uses, whichever runtime executes the network. Two runtimes implement it, both built
// from a TF.js graph model (tfjs_model.hpp):
//   - opencv:  OpenCV's cv::dnn, through the TF.js -> GraphDef loader (tfjs_graph.hpp);
//   - xnnpack: an XNNPACK subgraph built from the model's nodes (xnnpack_runner.cpp), one XNNPACK
//              runtime per input size, its own thread pool.
//
// Tensor layout, the same for both runtimes: dense float32, row-major, in the shape TensorFlow
// gives the tensor. Images are NHWC ([1, height, width, channels]) unless the model's input
// placeholder is declared NCHW (nanodet: [1, 3, H, W]), and outputs come in the model's own shapes
// (MoveNet heads: [1, H/4, W/4, C]), exactly as TensorFlow.js returns them. An int32 input
// placeholder (MoveNet's RGB 0..255) is fed as float values: its Cast is dropped.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::detect {

struct TfjsModel;

struct GraphTensor {
  std::vector<std::int64_t> shape;
  std::vector<float> values;  // row-major, shape's product many

  std::size_t size() const;  // product of the shape (1 for a scalar)
};

struct GraphTensorView {
  std::span<const std::int64_t> shape;
  std::span<const float> values;
};

enum class Backend { automatic, xnnpack, opencv };

// "auto", "xnnpack", "opencv"; throws std::invalid_argument naming the accepted values.
Backend parse_backend(std::string_view name);
std::string_view backend_name(Backend backend);

// True when this build has the XNNPACK runtime and the processor runs it.
bool xnnpack_available();

// The runtime `automatic` chooses: XNNPACK when available (measured faster than cv::dnn 4.6 on
// every model and size it was checked on; docs/models.md), else cv::dnn.
Backend resolve_backend(Backend requested);

struct RunnerOptions {
  Backend backend = Backend::automatic;
  // Threads of this network. XNNPACK: its own pool; 0 and 1: the calling thread only (its pool
  // spins while it waits: measured slower than one thread whenever other work shares the cores,
  // docs/models.md). cv::dnn: the process-wide cv::setNumThreads (the last runner made decides);
  // 0: OpenCV's default.
  int threads = 0;
  // Feed the network at this node instead of its input placeholder (empty: the placeholder), e.g.
  // single-pose MoveNet at "StatefulPartitionedCall/sub", after the batch-of-one reshuffles of
  // its int32 input, to run a batch of crops (a bypassed node such as "stack" means its input).
  // The node's own inputs are then not needed.
  std::string input_node;
};

class GraphRunner {
 public:
  virtual ~GraphRunner() = default;

  // Runs the network on `input` (shaped as the model's input; sizes the model accepts) and
  // fills `outputs` with the requested outputs, in the order they were requested. Reuses the
  // vectors' storage from call to call. Throws std::invalid_argument for an input of the wrong
  // rank or size, std::runtime_error when the runtime fails.
  virtual void run(const GraphTensorView& input, std::vector<GraphTensor>& outputs) = 0;

  virtual Backend backend() const = 0;
};

// Loads `model_json` for the named outputs ("node" or "node:1"). Throws std::runtime_error naming
// the model file: unreadable or inconsistent files, outputs the graph lacks, every operation the
// chosen runtime does not support (by op and node name; ModelError, which also names the command
// that fetches the models), or `xnnpack` asked in a build without it.
std::unique_ptr<GraphRunner> make_graph_runner(const std::filesystem::path& model_json,
                                               std::span<const std::string> outputs,
                                               const RunnerOptions& options);
// The same from a model already read (several runners of one model share its weights).
// `automatic` falls back to cv::dnn when XNNPACK is not given for one of the model's operations.
std::unique_ptr<GraphRunner> make_graph_runner(std::shared_ptr<const TfjsModel> model,
                                               std::span<const std::string> outputs,
                                               const RunnerOptions& options);

}  // namespace mocap::detect
