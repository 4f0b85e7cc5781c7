#pragma once
// MoveNet MultiPose's CNN (backbone, FPN and the six heads) in OpenCV's cv::dnn, loaded from the
// TF.js model. OpenCV stays inside the .cpp file.

#include <filesystem>
#include <memory>

#include "core/image_buffer.hpp"
#include "detect/movenet_decoder.hpp"

namespace mocap::detect {

class MovenetNetwork {
 public:
  // Throws std::runtime_error when the model cannot be read or converted.
  explicit MovenetNetwork(const std::filesystem::path& model_json);
  ~MovenetNetwork();
  MovenetNetwork(MovenetNetwork&&) noexcept;
  MovenetNetwork& operator=(MovenetNetwork&&) noexcept;

  // The heads for one input tensor: an RGB or BGR image, values 0..255, width and height
  // multiples of 32 (the model's strides need them). Throws std::invalid_argument otherwise.
  MovenetHeads run(const ImageBuffer& tensor);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::detect
