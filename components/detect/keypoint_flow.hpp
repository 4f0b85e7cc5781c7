#pragma once
// Keypoints carried from one frame to the next by sparse optical flow (pyramidal Lucas-Kanade,
// OpenCV's calcOpticalFlowPyrLK) with a forward-backward check: a point is moved into the new
// frame, moved back, and kept only when it lands near where it started (Kalal, Mikolajczyk and
// Matas, "Forward-Backward Error", ICPR 2010). Used by the top-down detector to skip the keypoint
// network for a person on the frames between its passes. OpenCV stays in the .cpp file.

#include <cstdint>
#include <memory>
#include <span>

#include "core/image_buffer.hpp"

namespace mocap::detect {

struct FlowPoint {
  float x = 0, y = 0;
};

struct KeypointFlowOptions {
  int window = 21;  // search window side in pixels at each pyramid level (OpenCV's default)
  int levels = 3;   // pyramid levels above the image (OpenCV's default)
};

class KeypointFlow {
 public:
  explicit KeypointFlow(const KeypointFlowOptions& options = {});
  ~KeypointFlow();
  KeypointFlow(const KeypointFlow&) = delete;
  KeypointFlow& operator=(const KeypointFlow&) = delete;

  // The frame points are moved into next; the one before becomes where they come from. Any
  // pixel format; throws std::invalid_argument on an empty frame.
  void next_frame(const ImageBuffer& frame);
  // Whether there is a frame before the latest one (and both have the same size).
  bool ready() const;
  // Moves points of the previous frame into the latest one. moved[i] is valid where ok[i] is 1:
  // found, inside the frame, and back-tracked to within max_error[i] pixels of from[i]. All spans
  // have the same length.
  void track(std::span<const FlowPoint> from, std::span<const float> max_error,
             std::span<FlowPoint> moved, std::span<std::uint8_t> ok);
  // Forget the frames (a new video).
  void reset();

 private:
  struct State;
  KeypointFlowOptions options_;
  std::unique_ptr<State> state_;
};

}  // namespace mocap::detect
