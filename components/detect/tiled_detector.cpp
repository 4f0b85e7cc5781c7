#include "detect/tiled_detector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "detect/person_boxes.hpp"

namespace mocap::detect {
namespace {

void check(const TileOptions& o) {
  if (o.columns < 1 || o.rows < 1 || o.columns * o.rows > 64)
    throw std::invalid_argument("tiles: 1 to 64 tiles (columns x rows)");
  if (!(o.overlap >= 0.0f && o.overlap < 0.9f))
    throw std::invalid_argument("tiles: overlap must lie in [0, 0.9)");
  if (o.tile_input_size < 32 || o.tile_input_size % 32 || o.frame_input_size < 0 ||
      o.frame_input_size % 32)
    throw std::invalid_argument("tiles: input sizes must be multiples of 32");
}

RunnerOptions runner_options(const TileOptions& o) {
  RunnerOptions r;
  r.backend = o.backend;
  r.threads = o.threads;
  return r;
}

// The image inside `rect`, sharing the frame's pixels.
ImageBuffer sub_image(const ImageBuffer& frame, const PixelRect& rect) {
  const std::byte* start = frame.data() + static_cast<std::size_t>(rect.y) * frame.stride() +
                           static_cast<std::size_t>(rect.x) * bytes_per_pixel(frame.format());
  return ImageBuffer(rect.width, rect.height, frame.stride(), frame.format(), frame.owner(), start);
}

// Shifts a person found in a tile into frame pixels.
void to_frame(MovenetPerson& p, const PixelRect& rect) {
  p.box.x += static_cast<float>(rect.x);
  p.box.y += static_cast<float>(rect.y);
  for (Keypoint2D& k : p.keypoints) {
    k.x += static_cast<float>(rect.x);
    k.y += static_cast<float>(rect.y);
  }
}

// A person cut by a tile edge that is not a frame edge is half a person: the whole frame or the
// neighbouring tile sees them better, so such a find loses against an uncut one.
bool cut_by_inner_edge(const MovenetPerson& p, const PixelRect& r, int width, int height) {
  const float margin = 2.0f;
  const Box2D& b = p.box;
  return (r.x > 0 && b.x <= r.x + margin) || (r.y > 0 && b.y <= r.y + margin) ||
         (r.x + r.width < width && b.x + b.width >= r.x + r.width - margin) ||
         (r.y + r.height < height && b.y + b.height >= r.y + r.height - margin);
}

}  // namespace

std::vector<PixelRect> tile_grid(int width, int height, int columns, int rows, float overlap) {
  std::vector<PixelRect> tiles;
  // n tiles of side s overlapping by o·s cover n·s − (n−1)·o·s = the frame's side.
  const auto side = [&](int total, int n) {
    return static_cast<int>(std::ceil(total / (n - (n - 1) * overlap)));
  };
  const int tw = std::min(width, side(width, columns)), th = std::min(height, side(height, rows));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      const int x = columns == 1 ? 0 : (width - tw) * c / (columns - 1);
      const int y = rows == 1 ? 0 : (height - th) * r / (rows - 1);
      tiles.push_back({x, y, tw, th});
    }
  }
  return tiles;
}

TiledDetector::TiledDetector(const std::filesystem::path& model_json, const TileOptions& options)
    : options_((check(options), options)), network_(model_json, runner_options(options)) {}

std::vector<MovenetPerson> TiledDetector::detect(const ImageBuffer& frame) {
  std::vector<MovenetPerson> found, cut;
  const auto run = [&](const ImageBuffer& image, int input_size) {
    const MovenetInput input = prepare_movenet_input(image, input_size);
    network_.run(input.tensor, heads_);
    return select_people(decode_movenet(heads_), input.mapping, options_.thresholds);
  };
  if (options_.frame_input_size > 0) found = run(frame, options_.frame_input_size);
  for (const PixelRect& rect : tile_grid(frame.width(), frame.height(), options_.columns,
                                         options_.rows, options_.overlap)) {
    for (MovenetPerson& p : run(sub_image(frame, rect), options_.tile_input_size)) {
      const bool is_cut = cut_by_inner_edge(p, rect, frame.width(), frame.height());
      to_frame(p, rect);
      (is_cut ? cut : found).push_back(std::move(p));
    }
  }
  // Uncut finds first, then the cut ones only where nobody was found.
  std::vector<MovenetPerson> people =
      remove_duplicates(std::move(found), options_.duplicate_overlap);
  for (MovenetPerson& p : remove_duplicates(std::move(cut), options_.duplicate_overlap)) {
    const bool seen = std::any_of(people.begin(), people.end(), [&](const MovenetPerson& k) {
      const float x0 = std::max(k.box.x, p.box.x), y0 = std::max(k.box.y, p.box.y);
      const float x1 = std::min(k.box.x + k.box.width, p.box.x + p.box.width);
      const float y1 = std::min(k.box.y + k.box.height, p.box.y + p.box.height);
      const float inter = std::max(0.0f, x1 - x0) * std::max(0.0f, y1 - y0);
      return inter > 0.5f * p.box.width * p.box.height;  // mostly inside someone found
    });
    if (!seen) people.push_back(std::move(p));
  }
  std::stable_sort(
      people.begin(), people.end(),
      [](const MovenetPerson& a, const MovenetPerson& b) { return a.score > b.score; });
  return people;
}

}  // namespace mocap::detect
