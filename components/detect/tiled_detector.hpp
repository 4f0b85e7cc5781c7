#pragma once
// MoveNet MultiPose on overlapping tiles of a large frame, for small and distant people: each tile
// is scaled so that its long side is the network input, so a person in it is larger than in the
// whole frame at the same input size, and each tile finds up to 6 people (the model's cap per
// image), so the frame has no cap. A pass over the whole frame finds the people too large for a
// tile. People found twice (in two tiles, or in a tile and the whole frame) are kept once.

#include <filesystem>
#include <vector>

#include "core/image_buffer.hpp"
#include "detect/movenet_decoder.hpp"
#include "detect/movenet_detector.hpp"

namespace mocap::detect {

struct TileOptions {
  int columns = 2, rows = 2;
  float overlap = 0.25f;       // share of a tile's side shared with its neighbour
  int tile_input_size = 256;   // network input long side per tile (multiple of 32)
  int frame_input_size = 256;  // the whole-frame pass (0: none)
  MovenetThresholds thresholds;
  float duplicate_overlap = 0.5f;  // people whose boxes overlap more are one
  // The network runtime and its threads, as MovenetOptions (graph_runner.hpp).
  Backend backend = Backend::automatic;
  int threads = 0;
};

// The tiles of a frame: columns × rows rectangles in frame pixels, overlapping by `overlap` of
// their side, covering the frame.
struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
};
std::vector<PixelRect> tile_grid(int width, int height, int columns, int rows, float overlap);

class TiledDetector {
 public:
  // Throws std::invalid_argument for bad options, std::runtime_error when the model fails.
  TiledDetector(const std::filesystem::path& model_json, const TileOptions& options);

  std::vector<MovenetPerson> detect(const ImageBuffer& frame);
  const TileOptions& options() const { return options_; }
  Backend backend() const { return network_.backend(); }

 private:
  TileOptions options_;
  MovenetNetwork network_;
  MovenetHeads heads_;  // reused from pass to pass
};

}  // namespace mocap::detect
