#include "detect/person_proposals.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "detect/image_tensor.hpp"

namespace mocap::detect {

std::vector<SquareRegion> proposal_tiles(int width, int height, int tiles, bool whole_frame) {
  if (tiles < 1) throw std::invalid_argument("the person detector needs at least one tile");
  const float w = static_cast<float>(width), h = static_cast<float>(height);
  const SquareRegion whole{w / 2, h / 2, 0.0f};
  if (tiles == 1 || width == height) return {whole};
  const bool wide = width > height;
  const float side = wide ? h : w, span = (wide ? w : h) - side;
  std::vector<SquareRegion> out;
  for (int i = 0; i < tiles; ++i) {
    const float centre = side / 2 + span * static_cast<float>(i) / static_cast<float>(tiles - 1);
    out.push_back(wide ? SquareRegion{centre, h / 2, side} : SquareRegion{w / 2, centre, side});
  }
  if (whole_frame) out.push_back(whole);
  return out;
}

std::pair<int, int> centernet_input_at_aspect(int width, int height) {
  constexpr int kStride = 32;
  const int short_side = std::min(width, height), long_side = std::max(width, height);
  const int scaled = short_side > 0
                         ? static_cast<int>(std::lround(static_cast<double>(long_side) *
                                                        kCenternetInput / short_side / kStride)) *
                               kStride
                         : kCenternetInput;
  const int other = std::max(kCenternetInput, scaled);
  return width >= height ? std::pair{kCenternetInput, other} : std::pair{other, kCenternetInput};
}

std::vector<Detection> propose_people(CenternetNetwork& network, const ImageBuffer& frame,
                                      const ProposalOptions& options, GraphTensor& input) {
  const std::vector<SquareRegion> tiles =
      proposal_tiles(frame.width(), frame.height(), options.tiles, options.whole_frame);
  const bool wide = frame.width() >= frame.height();
  std::vector<Detection> all;
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    const SquareRegion& r = tiles[t];
    if (r.side != 0 && network.input_height() != network.input_width())
      throw std::invalid_argument("person detector tiles need a square network input");
    image_batch(input, 1, network.input_height(), network.input_width());
    if (r.side == 0) {
      fill_stretched(frame, input, 0);
    } else {
      fill_region(frame, r, input, 0);
    }
    const std::vector<GraphTensor>& heads = network.run(input);
    std::vector<Detection> found =
        decode_centernet(heads[0], heads[1], kCenternetPersonClass, options.min_score, -1);
    // A tile's share of the long side: up to the middle of its overlap with each neighbour tile.
    // The whole frame (side 0) keeps everything it finds.
    const float centre = wide ? r.cx : r.cy;
    const auto tile_centre = [&](std::size_t i) {
      return tiles[i].side == 0 ? 0.0f : (wide ? tiles[i].cx : tiles[i].cy);
    };
    const bool has_previous = r.side != 0 && t > 0 && tiles[t - 1].side != 0;
    const bool has_next = r.side != 0 && t + 1 < tiles.size() && tiles[t + 1].side != 0;
    const float low = has_previous ? (centre + tile_centre(t - 1)) / 2 : -1e9f;
    const float high = has_next ? (centre + tile_centre(t + 1)) / 2 : 1e9f;
    const float sx = r.side == 0 ? static_cast<float>(frame.width()) / network.input_width()
                                 : r.side / kCenternetInput;
    const float sy = r.side == 0 ? static_cast<float>(frame.height()) / network.input_height()
                                 : r.side / kCenternetInput;
    const float x0 = r.side == 0 ? 0 : r.cx - r.side / 2, y0 = r.side == 0 ? 0 : r.cy - r.side / 2;
    for (Detection& d : found) {
      d.box = {x0 + d.box.x * sx, y0 + d.box.y * sy, d.box.width * sx, d.box.height * sy};
      const float c = wide ? d.box.x + d.box.width / 2 : d.box.y + d.box.height / 2;
      if (c >= low && c < high) all.push_back(d);
    }
  }
  return suppress_overlaps(std::move(all), options.box_overlap);
}

}  // namespace mocap::detect
