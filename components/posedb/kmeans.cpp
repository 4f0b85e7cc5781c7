#include "posedb/kmeans.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>

#include "posedb/distance.hpp"
#include "posedb/nearest_centroid.hpp"
#include "posedb/parallel_chunks.hpp"
#include "posedb/search_checks.hpp"

namespace mocap::posedb {
namespace {

// Small enough for smooth progress and load balance, large enough to make scheduling free.
constexpr std::size_t kChunkRows = 4096;

// One phase's share of the caller's progress bar.
struct PhaseProgress {
  const std::function<void(double)>* callback;
  double start;
  double span;

  void operator()(double fraction) const {
    if (*callback) (*callback)(start + span * std::clamp(fraction, 0.0, 1.0));
  }
};

// The training rows: the whole matrix, or a uniformly random subset copied in input order so
// that the copy is read sequentially.
struct Sample {
  std::vector<float> storage;
  MatrixView view;
};

Sample draw_sample(const MatrixView& data, std::size_t size, std::mt19937_64& rng) {
  if (size >= data.rows) return {{}, data};
  std::vector<std::uint32_t> order(data.rows);
  std::iota(order.begin(), order.end(), 0u);
  for (std::size_t i = 0; i < size; ++i) {  // a partial Fisher-Yates shuffle
    std::uniform_int_distribution<std::size_t> pick(i, data.rows - 1);
    std::swap(order[i], order[pick(rng)]);
  }
  std::sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(size));
  Sample sample;
  sample.storage.reserve(size * static_cast<std::size_t>(data.dim));
  for (std::size_t i = 0; i < size; ++i) {
    sample.storage.insert(sample.storage.end(), data.row(order[i]), data.row(order[i]) + data.dim);
  }
  sample.view = {sample.storage.data(), size, data.dim};
  return sample;
}

// Picks a row with probability proportional to its weight (the D² rule of k-means++).
std::size_t pick_by_weight(const std::vector<float>& weight, double total, std::mt19937_64& rng) {
  if (total <= 0.0) {  // every row coincides with a centre already: any row will do
    return std::uniform_int_distribution<std::size_t>(0, weight.size() - 1)(rng);
  }
  const double target = std::uniform_real_distribution<double>(0.0, total)(rng);
  double cumulative = 0.0;
  std::size_t last_positive = 0;
  for (std::size_t i = 0; i < weight.size(); ++i) {
    if (weight[i] <= 0.0f) continue;
    cumulative += weight[i];
    last_positive = i;
    if (cumulative > target) return i;
  }
  return last_positive;  // only reached through rounding
}

// k-means++ seeding. A row's nearest centre can only change if the new centre is closer to
// its current centre than twice the row's distance (triangle inequality), so most rows skip the
// distance computation once a few hundred centres exist.
std::vector<float> seed_centroids(const MatrixView& sample, int clusters, std::mt19937_64& rng,
                                  const PhaseProgress& progress) {
  const auto dim = static_cast<std::size_t>(sample.dim);
  std::vector<float> centroids(static_cast<std::size_t>(clusters) * dim);
  std::vector<float> nearest(sample.rows, std::numeric_limits<float>::infinity());
  std::vector<std::uint32_t> owner(sample.rows, 0);
  std::vector<float> centre_gap(static_cast<std::size_t>(clusters));
  double total = 0.0;

  for (int c = 0; c < clusters; ++c) {
    const std::size_t pick =
        c == 0 ? std::uniform_int_distribution<std::size_t>(0, sample.rows - 1)(rng)
               : pick_by_weight(nearest, total, rng);
    float* centre = centroids.data() + static_cast<std::size_t>(c) * dim;
    std::copy(sample.row(pick), sample.row(pick) + dim, centre);
    for (int o = 0; o < c; ++o) {
      centre_gap[o] = squared_l2<0>(centre, centroids.data() + o * dim, sample.dim);
    }
    total = 0.0;
    for (std::size_t i = 0; i < sample.rows; ++i) {
      if (c == 0 || centre_gap[owner[i]] < 4.0f * nearest[i]) {
        const float d = squared_l2<0>(sample.row(i), centre, sample.dim);
        if (d < nearest[i]) {
          nearest[i] = d;
          owner[i] = static_cast<std::uint32_t>(c);
        }
      }
      total += nearest[i];
    }
    if (c % 64 == 0) progress(double(c) / clusters);
  }
  return centroids;
}

struct Assignment {
  std::vector<std::uint32_t> cluster;
  std::vector<float> distance;
};

void assign_rows(const MatrixView& rows, const MatrixView& centroids, int threads, Assignment& out,
                 const PhaseProgress& progress) {
  const NearestCentroid nearest(centroids);
  out.cluster.resize(rows.rows);
  out.distance.resize(rows.rows);
  const std::size_t chunks = (rows.rows + kChunkRows - 1) / kChunkRows;
  for_each_chunk(
      chunks, threads,
      [&](std::size_t chunk) {
        const std::size_t begin = chunk * kChunkRows;
        const std::size_t end = std::min(rows.rows, begin + kChunkRows);
        nearest.assign(rows, begin, end, out.cluster.data() + begin, out.distance.data() + begin);
      },
      [&](std::size_t done) { progress(double(done) / chunks); });
}

// Moves each centroid to the mean of its rows. A cluster left empty takes over the row farthest
// from its own centroid, so that no representative is wasted.
void update_centroids(const MatrixView& sample, const Assignment& assignment, int clusters,
                      std::vector<float>& centroids) {
  const auto dim = static_cast<std::size_t>(sample.dim);
  std::vector<double> sum(centroids.size(), 0.0);
  std::vector<std::size_t> count(static_cast<std::size_t>(clusters), 0);
  for (std::size_t i = 0; i < sample.rows; ++i) {
    const std::uint32_t c = assignment.cluster[i];
    ++count[c];
    const float* row = sample.row(i);
    for (std::size_t j = 0; j < dim; ++j) sum[c * dim + j] += row[j];
  }

  std::vector<std::size_t> farthest(sample.rows);
  std::iota(farthest.begin(), farthest.end(), std::size_t{0});
  const auto empty = static_cast<std::size_t>(std::count(count.begin(), count.end(), 0u));
  const std::size_t needed = std::min(empty, farthest.size());
  std::partial_sort(farthest.begin(), farthest.begin() + static_cast<std::ptrdiff_t>(needed),
                    farthest.end(), [&](std::size_t a, std::size_t b) {
                      const float da = assignment.distance[a], db = assignment.distance[b];
                      return da > db || (da == db && a < b);
                    });

  std::size_t next_far = 0;
  for (std::size_t c = 0; c < count.size(); ++c) {
    float* centre = centroids.data() + c * dim;
    if (count[c] > 0) {
      for (std::size_t j = 0; j < dim; ++j) centre[j] = float(sum[c * dim + j] / double(count[c]));
    } else if (next_far < needed) {
      const float* row = sample.row(farthest[next_far++]);
      std::copy(row, row + dim, centre);
    }
  }
}

void train_centroids(const MatrixView& sample, int clusters, const KMeansOptions& options,
                     std::vector<float>& centroids, const PhaseProgress& progress) {
  Assignment assignment;
  std::vector<std::uint32_t> previous;
  const int iterations = std::max(options.iterations, 0);
  for (int it = 0; it < iterations; ++it) {
    const PhaseProgress step{progress.callback, progress.start + progress.span * it / iterations,
                             progress.span / iterations};
    assign_rows(sample, {centroids.data(), static_cast<std::size_t>(clusters), sample.dim},
                options.threads, assignment, step);
    if (assignment.cluster == previous) break;  // converged: the means would not move
    update_centroids(sample, assignment, clusters, centroids);
    previous = assignment.cluster;
  }
}

}  // namespace

double inertia(const MatrixView& data, const MatrixView& centroids,
               std::span<const std::uint32_t> assignment) {
  double total = 0.0;
  for (std::size_t i = 0; i < data.rows; ++i) {
    total += squared_l2<0>(data.row(i), centroids.row(assignment[i]), data.dim);
  }
  return total;
}

KMeansResult kmeans(const MatrixView& data, const KMeansOptions& options) {
  check_matrix(data, "k-means");
  KMeansResult result;
  result.dim = data.dim;
  if (data.rows == 0) return result;
  if (options.clusters < 1) throw std::invalid_argument("k-means needs at least one cluster");

  std::mt19937_64 rng(options.seed);
  const std::size_t sample_rows =
      std::max(options.sample_size, static_cast<std::size_t>(options.clusters));
  const Sample sample = draw_sample(data, sample_rows, rng);
  const int clusters = static_cast<int>(std::min<std::size_t>(options.clusters, sample.view.rows));

  // Progress shares by rough cost, in units of row-centroid distances per row.
  const double seeding = double(sample.view.rows);
  const double training = double(sample.view.rows) * std::max(options.iterations, 0);
  const double assigning = double(data.rows);
  const double all = seeding + training + assigning;
  const auto* callback = &options.progress;

  result.centroids = seed_centroids(sample.view, clusters, rng, {callback, 0.0, seeding / all});
  train_centroids(sample.view, clusters, options, result.centroids,
                  {callback, seeding / all, training / all});
  Assignment assignment;
  assign_rows(data, result.centroid_view(), options.threads, assignment,
              {callback, (seeding + training) / all, assigning / all});
  result.assignment = std::move(assignment.cluster);
  result.inertia = std::accumulate(assignment.distance.begin(), assignment.distance.end(), 0.0);
  if (options.progress) options.progress(1.0);
  return result;
}

ClusterOrder group_by_cluster(std::span<const std::uint32_t> assignment, int clusters) {
  if (clusters < 0) throw std::invalid_argument("group_by_cluster: negative cluster count");
  ClusterOrder order;
  order.cluster_begin.assign(static_cast<std::size_t>(clusters) + 1, 0);
  for (const std::uint32_t c : assignment) {
    if (c >= static_cast<std::uint32_t>(clusters)) {
      throw std::invalid_argument("group_by_cluster: cluster id out of range");
    }
    ++order.cluster_begin[c + 1];
  }
  std::partial_sum(order.cluster_begin.begin(), order.cluster_begin.end(),
                   order.cluster_begin.begin());
  // A counting sort: stable, so rows keep their input order within a cluster.
  std::vector<std::uint32_t> next(order.cluster_begin.begin(), order.cluster_begin.end() - 1);
  order.permutation.resize(assignment.size());
  for (std::size_t i = 0; i < assignment.size(); ++i) {
    order.permutation[next[assignment[i]]++] = static_cast<std::uint32_t>(i);
  }
  return order;
}

}  // namespace mocap::posedb
