#include "posedb/nearest_centroid.hpp"

#include <algorithm>
#include <limits>

#include "posedb/distance.hpp"

namespace mocap::posedb {
namespace {

// Eight centroids are two SSE registers per row; four rows of a tile then need eight
// accumulators, which leaves registers for the panel loads and the broadcast point value.
constexpr int kPanelWidth = 8;
constexpr int kTileRows = 4;

}  // namespace

NearestCentroid::NearestCentroid(const MatrixView& centroids)
    : dim_(centroids.dim),
      centroids_(centroids.rows),
      panels_((centroids.rows + kPanelWidth - 1) / kPanelWidth),
      packed_(panels_ * static_cast<std::size_t>(centroids.dim) * kPanelWidth, 0.0f),
      half_norm_(panels_ * kPanelWidth, std::numeric_limits<float>::infinity()),
      rows_(centroids.data, centroids.data + centroids.rows * std::size_t(centroids.dim)) {
  for (std::size_t c = 0; c < centroids_; ++c) {
    const std::size_t panel = c / kPanelWidth;
    const std::size_t lane = c % kPanelWidth;
    const float* row = centroids.row(c);
    float norm = 0.0f;
    for (int j = 0; j < dim_; ++j) {
      packed_[(panel * dim_ + j) * kPanelWidth + lane] = row[j];
      norm += row[j] * row[j];
    }
    half_norm_[c] = 0.5f * norm;
  }
}

void NearestCentroid::assign_tile(const float* const* tile_points, std::uint32_t* index) const {
  float best_score[kTileRows][kPanelWidth];
  // Panel numbers are kept as floats (exact below 2^24) so that the selects below operate on one
  // type and vectorise.
  float best_panel[kTileRows][kPanelWidth] = {};
  std::fill(&best_score[0][0], &best_score[0][0] + kTileRows * kPanelWidth,
            std::numeric_limits<float>::infinity());

  for (std::size_t p = 0; p < panels_; ++p) {
    const float* panel = packed_.data() + p * dim_ * kPanelWidth;
    float dot[kTileRows][kPanelWidth] = {};
    for (int j = 0; j < dim_; ++j) {
      for (int r = 0; r < kTileRows; ++r) {
        const float x = tile_points[r][j];
        for (int l = 0; l < kPanelWidth; ++l) dot[r][l] += x * panel[j * kPanelWidth + l];
      }
    }
    const float* half_norm = half_norm_.data() + p * kPanelWidth;
    const auto panel_index = static_cast<float>(p);
    for (int r = 0; r < kTileRows; ++r) {
      for (int l = 0; l < kPanelWidth; ++l) {
        // Branch-free selects so that this loop vectorises too.
        const float score = half_norm[l] - dot[r][l];
        const bool better = score < best_score[r][l];
        best_score[r][l] = better ? score : best_score[r][l];
        best_panel[r][l] = better ? panel_index : best_panel[r][l];
      }
    }
  }

  for (int r = 0; r < kTileRows; ++r) {
    float score = std::numeric_limits<float>::infinity();
    std::uint32_t best = 0;
    for (int l = 0; l < kPanelWidth; ++l) {
      const auto c = static_cast<std::uint32_t>(best_panel[r][l]) * kPanelWidth + l;
      if (best_score[r][l] < score || (best_score[r][l] == score && c < best)) {
        score = best_score[r][l];
        best = c;
      }
    }
    index[r] = best;
  }
}

void NearestCentroid::assign(const MatrixView& points, std::size_t begin, std::size_t end,
                             std::uint32_t* index, float* distance) const {
  if (centroids_ == 0) return;
  for (std::size_t first = begin; first < end; first += kTileRows) {
    const std::size_t count = std::min<std::size_t>(kTileRows, end - first);
    // A short last tile repeats its last point rather than taking a slower path.
    const float* tile_points[kTileRows];
    std::uint32_t tile_index[kTileRows];
    for (int r = 0; r < kTileRows; ++r) {
      tile_points[r] = points.row(first + std::min<std::size_t>(r, count - 1));
    }
    assign_tile(tile_points, tile_index);
    for (std::size_t r = 0; r < count; ++r) {
      index[first - begin + r] = tile_index[r];
      distance[first - begin + r] =
          squared_l2<0>(tile_points[r], rows_.data() + tile_index[r] * std::size_t(dim_), dim_);
    }
  }
}

}  // namespace mocap::posedb
