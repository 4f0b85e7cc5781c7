#pragma once
// MoveNet MultiPose's CNN (backbone, FPN and the six heads), loaded from the TF.js model and run
// by either network runtime (graph_runner.hpp). The runtimes stay inside their .cpp files.

#include <filesystem>
#include <memory>
#include <vector>

#include "core/image_buffer.hpp"
#include "detect/graph_runner.hpp"
#include "detect/movenet_decoder.hpp"

namespace mocap::detect {

class MovenetNetwork {
 public:
  // Throws std::runtime_error when the model cannot be read or converted.
  explicit MovenetNetwork(const std::filesystem::path& model_json,
                          const RunnerOptions& options = {});
  ~MovenetNetwork();
  MovenetNetwork(MovenetNetwork&&) noexcept;
  MovenetNetwork& operator=(MovenetNetwork&&) noexcept;

  // The heads for one input tensor: an RGB or BGR image, values 0..255, width and height
  // multiples of 32 (the model's strides need them). Throws std::invalid_argument otherwise.
  MovenetHeads run(const ImageBuffer& tensor);
  // The same into `heads`, reusing its storage.
  void run(const ImageBuffer& tensor, MovenetHeads& heads);

  Backend backend() const;

 private:
  std::unique_ptr<GraphRunner> runner_;
  std::vector<float> input_;
  std::vector<GraphTensor> outputs_;
};

}  // namespace mocap::detect
