#pragma once
// Person boxes from MB3-CenterNet on a whole frame, optionally on overlapping square tiles.
// Stretching a wide frame to the detector's square 512 × 512 input squeezes people sideways
// (1280 × 720: by 0.40 across, 0.71 down) and shrinks them; square tiles of the frame's short
// side keep their shape, and each tile keeps the detections whose centre lies in its own share of
// the frame (the overlap split at its middle), so a person narrower than the overlap is found
// whole by exactly one tile. A person wider than the overlap (a close-up) is cut by every tile;
// `whole_frame` adds one pass over the whole frame stretched, which sees them whole. The
// detections of all passes are then thinned by NMS.

#include <utility>
#include <vector>

#include "core/image_buffer.hpp"
#include "detect/centernet.hpp"
#include "detect/image_tensor.hpp"

namespace mocap::detect {

struct ProposalOptions {
  float min_score = 0.3f;    // CenterNet person score
  float box_overlap = 0.5f;  // boxes overlapping more are one (NMS)
  // 1: the whole frame stretched to the input (the model's users' way). N > 1: N square tiles
  // of the frame's short side spread evenly along its long side (none when the frame is square).
  int tiles = 1;
  // With tiles > 1: one more pass over the whole frame stretched, for the people wider than the
  // tiles' overlap.
  bool whole_frame = false;
};

// The square regions the detector sees for a frame of width × height (one stretched region is
// returned as the frame's centre with side 0: callers stretch the whole frame), the whole frame
// last when `whole_frame` adds it to several tiles.
std::vector<SquareRegion> proposal_tiles(int width, int height, int tiles,
                                         bool whole_frame = false);

// The input (height, width) at which MB3-CenterNet sees a width × height frame at its own aspect:
// the short side at the model's 512, the long side scaled alike and rounded to the graph's stride
// of 32 (1280 × 720: 512 × 896, 768 × 576: 512 × 672; people 0.71 × 0.70 of their size instead of
// squeezed 0.40 × 0.71 across and down).
std::pair<int, int> centernet_input_at_aspect(int width, int height);

// Person detections in frame pixels, best first. `input` is the network's input, reused between
// calls. One whole-frame pass (tiles 1, or the whole frame added to tiles) is stretched to the
// network's input, whatever its shape; tiles need a square one. Throws std::invalid_argument for
// tiles < 1 or tiles on a network whose input is not square.
std::vector<Detection> propose_people(CenternetNetwork& network, const ImageBuffer& frame,
                                      const ProposalOptions& options, GraphTensor& input);

}  // namespace mocap::detect
