#pragma once
// Video frames into the networks' input: NHWC float RGB (0..255) in a GraphTensor
// (graph_runner.hpp), the layout both network runtimes take. A square region of the frame (a
// person's crop; black where it leaves the frame) or the whole frame stretched.

#include "core/image_buffer.hpp"
#include "core/messages.hpp"
#include "detect/graph_runner.hpp"

namespace mocap::detect {

// A square in frame pixels: centre and side.
struct SquareRegion {
  float cx = 0, cy = 0, side = 0;
};

// The square around a box, its side the box's longer side × padding (rtmlib's and MMPose's
// top-down convention pads by 1.25).
SquareRegion square_around(const Box2D& box, float padding);

// Shapes `batch` as [count, height, width, 3] and zeroes it, reusing its storage.
void image_batch(GraphTensor& batch, int count, int height, int width);

// Writes image n of `batch` from `region` of the frame (bilinear; black outside the frame).
// Throws std::invalid_argument for an empty frame, a degenerate region or n outside the batch.
void fill_region(const ImageBuffer& frame, const SquareRegion& region, GraphTensor& batch, int n);

// Writes image n of `batch` from the whole frame stretched to the tensor's size (bilinear).
void fill_stretched(const ImageBuffer& frame, GraphTensor& batch, int n);

}  // namespace mocap::detect
