#pragma once
// MoveNet MultiPose as a detector: any video frame in, people with COCO-17 keypoints in the
// frame's pixels out. It scales the frame so that its long side is `input_size`, pads the bottom
// and right edges with black up to multiples of 32 (the model needs them; tfjs-models pads the
// same way), runs the network and decodes the heads.

#include <filesystem>
#include <vector>

#include "core/image_buffer.hpp"
#include "detect/movenet_decoder.hpp"
#include "detect/movenet_network.hpp"

namespace mocap::detect {

struct MovenetOptions {
  // Long side of the tensor in pixels, a multiple of 32: 256 is the model card's choice and the
  // fastest useful size; 384-512 find small or distant people.
  int input_size = 256;
  MovenetThresholds thresholds;
  // The network runtime and its threads (graph_runner.hpp): XNNPACK threads are the detector's
  // own; cv::dnn's are process-wide (the last detector made decides). 0: the runtime's default.
  Backend backend = Backend::automatic;
  int threads = 0;
};

// The tensor the network is fed (rgb8, sides multiples of 32) and how it maps back.
struct MovenetInput {
  ImageBuffer tensor;
  TensorMapping mapping;
};

// Throws std::invalid_argument for an empty image or an input size that is not a positive
// multiple of 32.
MovenetInput prepare_movenet_input(const ImageBuffer& image, int input_size);

class MovenetDetector {
 public:
  // Throws std::invalid_argument for bad options, std::runtime_error when the model fails to load.
  MovenetDetector(const std::filesystem::path& model_json, const MovenetOptions& options);

  // People above the person threshold, best first; missing keypoints have NaN coordinates.
  std::vector<MovenetPerson> detect(const ImageBuffer& image);

  const MovenetOptions& options() const { return options_; }
  Backend backend() const { return network_.backend(); }

 private:
  MovenetOptions options_;
  MovenetNetwork network_;
  MovenetHeads heads_;  // reused from frame to frame
};

}  // namespace mocap::detect
