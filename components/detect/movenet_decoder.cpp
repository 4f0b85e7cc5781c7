#include "detect/movenet_decoder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace mocap::detect {
namespace {

// The graph's constants, as its float16 storage has them (copying them is what matches TF.js).
constexpr float kPeakTolerance = 1.0132790e-6f;     // |C - maxpool(C)| below it: a local peak
constexpr float kGaussianDenomRatio = 0.30004883f;  // × min(h, w)
constexpr float kValidKeypointScore = 0.126953125f;
constexpr int kPeakWindow = 5;

float sigmoid(float v) { return 1.0f / (1.0f + std::exp(-v)); }

// A head, NHWC without the batch: value (c, y, x) at [(y * width + x) * channels + c].
class Grid {
 public:
  Grid(const std::vector<float>& data, int width, int channels)
      : data_(data), w_(width), c_(channels) {}
  float at(int channel, int y, int x) const {
    return data_[(static_cast<std::size_t>(y) * w_ + x) * c_ + channel];
  }

 private:
  const std::vector<float>& data_;
  int w_, c_;
};

void check_size(const std::vector<float>& head, int channels, const MovenetHeads& heads,
                const char* name) {
  const auto expected = static_cast<std::size_t>(channels) * heads.height * heads.width;
  if (heads.height <= 0 || heads.width <= 0 || head.size() != expected)
    throw std::invalid_argument(std::string("MoveNet head '") + name + "' has " +
                                std::to_string(head.size()) + " values, expected " +
                                std::to_string(expected));
}

// Sigmoid of the centre map, kept only at 5×5 local maxima (TF's SAME max-pool ignores padding).
std::vector<float> centre_peaks(const MovenetHeads& heads) {
  const int h = heads.height, w = heads.width, r = kPeakWindow / 2;
  std::vector<float> c(heads.center.size());
  std::transform(heads.center.begin(), heads.center.end(), c.begin(), sigmoid);
  std::vector<float> peaks(c.size(), 0.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float m = -std::numeric_limits<float>::infinity();
      for (int yy = std::max(0, y - r); yy <= std::min(h - 1, y + r); ++yy)
        for (int xx = std::max(0, x - r); xx <= std::min(w - 1, x + r); ++xx)
          m = std::max(m, c[static_cast<std::size_t>(yy) * w + xx]);
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      if (std::fabs(c[i] - m) < kPeakTolerance) peaks[i] = c[i];
    }
  }
  return peaks;
}

// The k largest, descending; ties go to the lower index (TF's TopKV2).
std::vector<int> top_k(const std::vector<float>& values, int k) {
  std::vector<int> order(values.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return values[a] > values[b]; });
  order.resize(static_cast<std::size_t>(std::min<std::size_t>(k, order.size())));
  return order;
}

struct Instance {
  int cy = 0, cx = 0;  // integer centre cell
  float centre_score = 0;
  float ymin = 0, xmin = 0, ymax = 0, xmax = 0;     // clamped grid-cell box
  std::array<float, kMovenetKeypoints> ry{}, rx{};  // regressed joints, cells
};

Instance make_instance(const MovenetHeads& heads, int cell, float score) {
  const int h = heads.height, w = heads.width;
  const Grid bs(heads.box_scale, w, 2), bo(heads.box_offset, w, 2),
      kr(heads.regress, w, 2 * kMovenetKeypoints);
  Instance in;
  in.cy = cell / w;
  in.cx = cell % w;
  in.centre_score = score;
  const float cy = static_cast<float>(in.cy) + bo.at(0, in.cy, in.cx);
  const float cx = static_cast<float>(in.cx) + bo.at(1, in.cy, in.cx);
  const float bh = std::max(bs.at(0, in.cy, in.cx), 0.0f);
  const float bw = std::max(bs.at(1, in.cy, in.cx), 0.0f);
  const auto fh = static_cast<float>(h), fw = static_cast<float>(w);
  in.ymin = std::clamp(cy - bh / 2, 0.0f, fh);
  in.xmin = std::clamp(cx - bw / 2, 0.0f, fw);
  in.ymax = std::clamp(cy + bh / 2, 0.0f, fh);
  in.xmax = std::clamp(cx + bw / 2, 0.0f, fw);
  for (int k = 0; k < kMovenetKeypoints; ++k) {
    in.ry[k] = static_cast<float>(in.cy) + kr.at(2 * k, in.cy, in.cx);
    in.rx[k] = static_cast<float>(in.cx) + kr.at(2 * k + 1, in.cy, in.cx);
  }
  return in;
}

// The heatmap rescored by closeness to the instance's regressed joint, zero outside its box.
float rescored(const Instance& in, int k, int y, int x, float heat, float denom) {
  const auto fy = static_cast<float>(y), fx = static_cast<float>(x);
  if (!(in.ymin <= fy && fy < in.ymax && in.xmin <= fx && fx < in.xmax)) return 0.0f;
  const float dy = fy - in.ry[k], dx = fx - in.rx[k];
  return heat * std::exp(-(dy * dy + dx * dx) / denom);
}

struct Cell {
  int y = 0, x = 0;
};

// The first cell (row-major) of the largest rescored value; (0, 0) when all are zero, as an
// argmax over the whole grid (zero outside the box) gives.
Cell best_cell(const Instance& in, int k, const Grid& heat, float denom) {
  Cell best;
  float best_value = 0.0f;
  const int y0 = static_cast<int>(std::ceil(in.ymin)), x0 = static_cast<int>(std::ceil(in.xmin));
  for (int y = y0; static_cast<float>(y) < in.ymax; ++y) {
    for (int x = x0; static_cast<float>(x) < in.xmax; ++x) {
      const float v = rescored(in, k, y, x, sigmoid(heat.at(k, y, x)), denom);
      if (v > best_value) {
        best_value = v;
        best = {y, x};
      }
    }
  }
  return best;
}

MovenetRow make_row(const std::vector<Instance>& all, std::size_t i, const MovenetHeads& heads,
                    float denom) {
  const int h = heads.height, w = heads.width;
  const Grid heat(heads.heatmap, w, kMovenetKeypoints), ko(heads.offset, w, 2 * kMovenetKeypoints);
  const Instance& in = all[i];
  MovenetRow row{};
  float sum = 0.0f;
  int valid = 0;
  for (int k = 0; k < kMovenetKeypoints; ++k) {
    const Cell c = best_cell(in, k, heat, denom);
    const float heat_value = sigmoid(heat.at(k, c.y, c.x));
    float score = 0.0f;  // the graph takes the best of all instances at this cell
    for (const Instance& other : all)
      score = std::max(score, rescored(other, k, c.y, c.x, heat_value, denom));
    row[3 * k] = (static_cast<float>(c.y) + ko.at(2 * k, c.y, c.x)) / static_cast<float>(h);
    row[3 * k + 1] = (static_cast<float>(c.x) + ko.at(2 * k + 1, c.y, c.x)) / static_cast<float>(w);
    row[3 * k + 2] = score;
    if (score > kValidKeypointScore) {
      sum += score;
      ++valid;
    }
  }
  const int base = 3 * kMovenetKeypoints;
  row[base] = std::clamp(in.ymin / static_cast<float>(h), 0.0f, 1.0f);
  row[base + 1] = std::clamp(in.xmin / static_cast<float>(w), 0.0f, 1.0f);
  row[base + 2] = std::clamp(in.ymax / static_cast<float>(h), 0.0f, 1.0f);
  row[base + 3] = std::clamp(in.xmax / static_cast<float>(w), 0.0f, 1.0f);
  row[base + 4] = in.centre_score * sum / static_cast<float>(std::max(valid, 1));
  return row;
}

}  // namespace

std::array<MovenetRow, kMovenetInstances> decode_movenet(const MovenetHeads& heads) {
  check_size(heads.center, 1, heads, "center");
  check_size(heads.box_scale, 2, heads, "box_scale");
  check_size(heads.box_offset, 2, heads, "box_offset");
  check_size(heads.heatmap, kMovenetKeypoints, heads, "heatmap");
  check_size(heads.regress, 2 * kMovenetKeypoints, heads, "regress");
  check_size(heads.offset, 2 * kMovenetKeypoints, heads, "offset");

  const std::vector<float> peaks = centre_peaks(heads);
  std::vector<Instance> instances;
  for (const int cell : top_k(peaks, kMovenetInstances))
    instances.push_back(make_instance(heads, cell, peaks[cell]));
  const float denom = kGaussianDenomRatio * static_cast<float>(std::min(heads.height, heads.width));
  std::array<MovenetRow, kMovenetInstances> rows{};
  for (std::size_t i = 0; i < instances.size(); ++i) rows[i] = make_row(instances, i, heads, denom);
  return rows;
}

std::vector<MovenetPerson> select_people(const std::array<MovenetRow, kMovenetInstances>& rows,
                                         const TensorMapping& mapping,
                                         const MovenetThresholds& thresholds) {
  const auto tw = static_cast<float>(mapping.tensor_width);
  const auto th = static_cast<float>(mapping.tensor_height);
  const auto to_x = [&](float x) { return (x * tw - mapping.pad_left) / mapping.scale_x; };
  const auto to_y = [&](float y) { return (y * th - mapping.pad_top) / mapping.scale_y; };
  std::vector<MovenetPerson> people;
  for (const MovenetRow& row : rows) {
    const int base = 3 * kMovenetKeypoints;
    if (!(row[base + 4] >= thresholds.min_person_score)) continue;
    MovenetPerson p;
    p.score = row[base + 4];
    const float x0 = to_x(row[base + 1]), y0 = to_y(row[base]);
    p.box = {x0, y0, to_x(row[base + 3]) - x0, to_y(row[base + 2]) - y0};
    for (int k = 0; k < kMovenetKeypoints; ++k) {
      const float score = row[3 * k + 2];
      if (score >= thresholds.min_keypoint_score)
        p.keypoints[k] = {to_x(row[3 * k + 1]), to_y(row[3 * k]), score};
      else
        p.keypoints[k] = {std::nanf(""), std::nanf(""), 0.0f};
    }
    people.push_back(p);
  }
  std::stable_sort(people.begin(), people.end(),
                   [](const auto& a, const auto& b) { return a.score > b.score; });
  return people;
}

}  // namespace mocap::detect
