// The nearest-neighbour methods of the pose database on synthetic clustered data: Gaussian blobs in
// 28 dimensions, like normalised 2D poses (values within about [-1, 1], many similar poses).

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "posedb/cluster_search.hpp"
#include "posedb/exact_search.hpp"
#include "posedb/flann_search.hpp"
#include "posedb/kmeans.hpp"
#include "posedb/search.hpp"
#ifdef MOCAP_HAVE_FAISS
#include "posedb/faiss_search.hpp"
#endif

namespace mocap::posedb {
namespace {

constexpr int kDim = 28;

// Rows of the recall tests. The sanitizer build (-O1, every access checked, README "Sanitizers")
// runs these searches two orders of magnitude slower than Release, so it searches a quarter of
// the rows with the same checks; Release keeps the full size.
#if defined(__SANITIZE_ADDRESS__)
constexpr std::size_t kRecallRows = 15'000;
#else
constexpr std::size_t kRecallRows = 60'000;
#endif

// Owns a row-major matrix and views it.
struct Matrix {
  std::vector<float> values;
  int dim = kDim;

  std::size_t rows() const { return values.size() / dim; }
  MatrixView view() const { return {values.data(), rows(), dim}; }
  const float* row(std::size_t i) const { return values.data() + i * dim; }
};

// Blob centres are drawn once per seed; `rows` points are scattered around them.
Matrix gaussian_blobs(std::size_t rows, int blobs, float spread, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> centre_value(-0.7f, 0.7f);
  std::vector<float> centres(static_cast<std::size_t>(blobs) * kDim);
  for (float& v : centres) v = centre_value(rng);
  std::uniform_int_distribution<int> pick_blob(0, blobs - 1);
  std::normal_distribution<float> noise(0.0f, spread);
  Matrix m;
  m.values.resize(rows * kDim);
  for (std::size_t i = 0; i < rows; ++i) {
    const float* centre = centres.data() + pick_blob(rng) * kDim;
    for (int j = 0; j < kDim; ++j) m.values[i * kDim + j] = centre[j] + noise(rng);
  }
  return m;
}

// Database and held-out queries drawn from the same blobs.
struct Dataset {
  Matrix data;
  Matrix queries;
};

Dataset blob_dataset(std::size_t rows, std::size_t queries, std::uint32_t seed = 7) {
  Matrix all = gaussian_blobs(rows + queries, 64, 0.08f, seed);
  Dataset set;
  set.data.values.assign(all.values.begin(), all.values.begin() + rows * kDim);
  set.queries.values.assign(all.values.begin() + rows * kDim, all.values.end());
  return set;
}

// The obvious implementation: every distance in double precision, then a full sort.
std::vector<Neighbor> naive_search(const MatrixView& m, const float* query, const float* weights,
                                   int k) {
  std::vector<std::pair<double, std::uint32_t>> all;
  for (std::size_t i = 0; i < m.rows; ++i) {
    double sum = 0.0;
    for (int j = 0; j < m.dim; ++j) {
      const double w = weights ? weights[j] : 1.0;
      if (w == 0.0) continue;
      const double d = double(query[j]) - m.row(i)[j];
      sum += w * d * d;
    }
    all.emplace_back(sum, static_cast<std::uint32_t>(i));
  }
  std::sort(all.begin(), all.end());
  std::vector<Neighbor> out;
  for (std::size_t i = 0; i < std::min<std::size_t>(all.size(), std::max(k, 0)); ++i) {
    out.push_back({all[i].second, static_cast<float>(all[i].first)});
  }
  return out;
}

void expect_sorted(const std::vector<Neighbor>& out) {
  for (std::size_t i = 1; i < out.size(); ++i) {
    EXPECT_LE(out[i - 1].distance, out[i].distance) << "at " << i;
  }
}

// Recall@k, counting ties by distance: a returned neighbour is right if it is no farther than
// the exact k-th neighbour.
double recall(const SearchIndex& approximate, const SearchIndex& exact, const Matrix& queries,
              int k) {
  std::vector<Neighbor> truth, found;
  std::size_t hits = 0, wanted = 0;
  for (std::size_t q = 0; q < queries.rows(); ++q) {
    exact.search(queries.row(q), nullptr, k, truth);
    approximate.search(queries.row(q), nullptr, k, found);
    const float limit = truth.back().distance * (1.0f + 1e-5f) + 1e-7f;
    std::set<std::uint32_t> seen;
    for (const Neighbor& n : found) {
      if (n.distance <= limit && seen.insert(n.index).second) ++hits;
    }
    wanted += truth.size();
  }
  return double(hits) / double(wanted);
}

// Fraction of sampled rows whose own query returns them first at distance 0.
double self_hit_rate(const SearchIndex& index, const Matrix& data, std::size_t samples) {
  std::vector<Neighbor> out;
  std::size_t hits = 0;
  const std::size_t step = std::max<std::size_t>(1, data.rows() / samples);
  std::size_t tried = 0;
  for (std::size_t i = 0; i < data.rows(); i += step, ++tried) {
    index.search(data.row(i), nullptr, 5, out);
    if (!out.empty() && out[0].index == i && out[0].distance <= 1e-6f) ++hits;
  }
  return double(hits) / double(tried);
}

// A k-means clustering with the rows stored sorted by cluster, as the database file does.
struct SortedClusters {
  Matrix rows;
  KMeansResult kmeans;
  ClusterOrder order;
  std::vector<std::uint32_t> original;  // original[sorted row] = input row
};

SortedClusters sort_by_clusters(const Matrix& data, int clusters, std::uint64_t seed = 3) {
  SortedClusters s;
  KMeansOptions options;
  options.clusters = clusters;
  options.sample_size = 20'000;
  options.seed = seed;
  s.kmeans = kmeans(data.view(), options);
  s.order = group_by_cluster(s.kmeans.assignment, s.kmeans.clusters());
  s.rows.values.reserve(data.values.size());
  for (const std::uint32_t i : s.order.permutation) {
    s.rows.values.insert(s.rows.values.end(), data.row(i), data.row(i) + kDim);
  }
  s.original = s.order.permutation;
  return s;
}

ClusterSearch cluster_search(const SortedClusters& s, int probe) {
  return {s.rows.view(), s.kmeans.centroid_view(), s.order.cluster_begin, probe};
}

// ---------------------------------------------------------------------------------------------
// Exact search

TEST(ExactSearch, MatchesNaiveReference) {
  const Dataset set = blob_dataset(20'000, 50);
  const ExactSearch exact(set.data.view());
  std::vector<Neighbor> out;
  for (const int k : {1, 10, 64}) {
    for (std::size_t q = 0; q < set.queries.rows(); ++q) {
      exact.search(set.queries.row(q), nullptr, k, out);
      const auto reference = naive_search(set.data.view(), set.queries.row(q), nullptr, k);
      ASSERT_EQ(out.size(), reference.size());
      for (std::size_t i = 0; i < out.size(); ++i) {
        EXPECT_EQ(out[i].index, reference[i].index) << "query " << q << " k " << k << " rank " << i;
        EXPECT_NEAR(out[i].distance, reference[i].distance, 1e-5f * (1 + reference[i].distance));
      }
    }
  }
}

TEST(ExactSearch, FindsEveryRowItself) {
  const Dataset set = blob_dataset(5'000, 0);
  const ExactSearch exact(set.data.view());
  EXPECT_EQ(self_hit_rate(exact, set.data, 5'000), 1.0);
}

TEST(ExactSearch, WorksForAnyDimension) {
  Matrix m;
  m.dim = 5;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 5; ++j) m.values.push_back(float(i) + 0.1f * j);
  }
  const ExactSearch exact(m.view());
  const float query[5] = {41.9f, 42.0f, 42.1f, 42.2f, 42.3f};
  std::vector<Neighbor> out;
  exact.search(query, nullptr, 3, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].index, 42u);
  EXPECT_EQ(std::set<std::uint32_t>({out[1].index, out[2].index}),
            (std::set<std::uint32_t>{41u, 43u}));
  expect_sorted(out);
}

TEST(ExactSearch, BreaksTiesByIndex) {
  Matrix m;
  m.values.assign(10 * kDim, 0.5f);  // ten identical rows
  const ExactSearch exact(m.view());
  std::vector<Neighbor> out;
  exact.search(m.row(0), nullptr, 4, out);
  ASSERT_EQ(out.size(), 4u);
  for (std::uint32_t i = 0; i < 4; ++i) EXPECT_EQ(out[i].index, i);
}

// ---------------------------------------------------------------------------------------------
// Weights

TEST(WeightedSearch, IgnoresDimensionsOfWeightZero) {
  const Dataset set = blob_dataset(10'000, 20);
  const ExactSearch exact(set.data.view());
  std::vector<float> weights(kDim, 1.0f);
  for (const int missing : {0, 1, 10, 11}) weights[missing] = 0.0f;  // two joints not detected

  std::vector<Neighbor> out;
  for (std::size_t r = 0; r < 200; r += 17) {
    std::vector<float> query(set.data.row(r), set.data.row(r) + kDim);
    for (int j = 0; j < kDim; ++j) {
      if (weights[j] == 0.0f) query[j] = std::numeric_limits<float>::quiet_NaN();
    }
    exact.search(query.data(), weights.data(), 3, out);
    ASSERT_FALSE(out.empty());
    EXPECT_EQ(out[0].index, r);
    EXPECT_EQ(out[0].distance, 0.0f);
  }
}

TEST(WeightedSearch, MatchesNaiveReferenceWithNonBinaryWeights) {
  const Dataset set = blob_dataset(10'000, 20);
  const ExactSearch exact(set.data.view());
  std::vector<float> weights(kDim);
  for (int j = 0; j < kDim; ++j) weights[j] = float(j % 4) * 0.5f;  // 0, 0.5, 1, 1.5
  std::vector<Neighbor> out;
  for (std::size_t q = 0; q < set.queries.rows(); ++q) {
    exact.search(set.queries.row(q), weights.data(), 10, out);
    const auto reference = naive_search(set.data.view(), set.queries.row(q), weights.data(), 10);
    ASSERT_EQ(out.size(), reference.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
      EXPECT_EQ(out[i].index, reference[i].index);
      EXPECT_NEAR(out[i].distance, reference[i].distance, 1e-5f * (1 + reference[i].distance));
    }
  }
}

TEST(WeightedSearch, RejectsNegativeOrNonFiniteWeights) {
  const Dataset set = blob_dataset(100, 1);
  const ExactSearch exact(set.data.view());
  std::vector<float> weights(kDim, 1.0f);
  std::vector<Neighbor> out;
  weights[3] = -1.0f;
  EXPECT_THROW(exact.search(set.queries.row(0), weights.data(), 1, out), std::invalid_argument);
  weights[3] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(exact.search(set.queries.row(0), weights.data(), 1, out), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// k-means

TEST(KMeans, IsDeterministicForASeedWhateverTheThreadCount) {
  const Dataset set = blob_dataset(30'000, 0);
  KMeansOptions options;
  options.clusters = 100;
  options.sample_size = 10'000;
  options.seed = 11;
  options.threads = 1;
  const KMeansResult one = kmeans(set.data.view(), options);
  options.threads = 2;
  const KMeansResult two = kmeans(set.data.view(), options);
  const KMeansResult again = kmeans(set.data.view(), options);
  EXPECT_EQ(one.centroids, two.centroids);
  EXPECT_EQ(one.assignment, two.assignment);
  EXPECT_EQ(two.centroids, again.centroids);
  EXPECT_EQ(two.inertia, again.inertia);

  options.seed = 12;
  EXPECT_NE(kmeans(set.data.view(), options).centroids, one.centroids);
}

TEST(KMeans, ReducesInertiaFarBelowRandomAssignment) {
  const Dataset set = blob_dataset(30'000, 0);
  KMeansOptions options;
  options.clusters = 64;
  options.sample_size = 10'000;
  const KMeansResult result = kmeans(set.data.view(), options);
  ASSERT_EQ(result.clusters(), 64);
  ASSERT_EQ(result.assignment.size(), set.data.rows());
  EXPECT_NEAR(result.inertia, inertia(set.data.view(), result.centroid_view(), result.assignment),
              1e-3 * result.inertia);

  std::mt19937 rng(5);
  std::uniform_int_distribution<std::uint32_t> any(0, 63);
  std::vector<std::uint32_t> random(set.data.rows());
  for (auto& c : random) c = any(rng);
  const double random_inertia = inertia(set.data.view(), result.centroid_view(), random);
  EXPECT_LT(result.inertia, 0.2 * random_inertia);

  // One cluster would cost the total variance. Blobs are 0.08 wide, about 1.1 apart per
  // dimension: k-means++ may merge a few of them (its known weakness with as many clusters as
  // blobs), but most must be found.
  std::vector<float> mean(kDim, 0.0f);
  for (std::size_t i = 0; i < set.data.rows(); ++i) {
    for (int j = 0; j < kDim; ++j) mean[j] += set.data.row(i)[j] / float(set.data.rows());
  }
  const std::vector<std::uint32_t> one_cluster(set.data.rows(), 0);
  const double total = inertia(set.data.view(), {mean.data(), 1, kDim}, one_cluster);
  EXPECT_LT(result.inertia, 0.15 * total);
}

TEST(KMeans, AssignsEveryRowToItsNearestCentroid) {
  const Dataset set = blob_dataset(20'000, 0);
  KMeansOptions options;
  options.clusters = 300;
  options.sample_size = 5'000;
  const KMeansResult result = kmeans(set.data.view(), options);
  const ExactSearch centroids(result.centroid_view());
  std::vector<Neighbor> nearest;
  for (std::size_t i = 0; i < set.data.rows(); i += 7) {
    centroids.search(set.data.row(i), nullptr, 1, nearest);
    const float assigned = inertia({set.data.row(i), 1, kDim}, result.centroid_view(),
                                   std::span(&result.assignment[i], 1));
    // The kernel ranks by |c|²/2 - x.c, so only near-ties may go either way.
    EXPECT_NEAR(assigned, nearest[0].distance, 1e-5f) << "row " << i;
  }
}

TEST(KMeans, ReportsProgressOnTheCallingThreadUpToOne) {
  const Dataset set = blob_dataset(20'000, 0);
  KMeansOptions options;
  options.clusters = 50;
  options.sample_size = 5'000;
  std::vector<double> reports;
  options.progress = [&](double f) { reports.push_back(f); };
  kmeans(set.data.view(), options);
  ASSERT_GE(reports.size(), 3u);
  EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
  EXPECT_GE(reports.front(), 0.0);
  EXPECT_DOUBLE_EQ(reports.back(), 1.0);
}

TEST(KMeans, HandlesFewRowsAndEmptyInput) {
  const Dataset set = blob_dataset(10, 0);
  KMeansOptions options;
  options.clusters = 50;
  const KMeansResult few = kmeans(set.data.view(), options);
  EXPECT_EQ(few.clusters(), 10);
  EXPECT_DOUBLE_EQ(few.inertia, 0.0);  // every row is its own centroid

  const KMeansResult none = kmeans({nullptr, 0, kDim}, options);
  EXPECT_EQ(none.clusters(), 0);
  EXPECT_TRUE(none.assignment.empty());

  options.clusters = 0;
  EXPECT_THROW(kmeans(set.data.view(), options), std::invalid_argument);
}

TEST(KMeans, DuplicateRowsLeaveNoClusterEmptyWhenAvoidable) {
  Matrix m = gaussian_blobs(2'000, 4, 0.05f, 9);
  m.values.resize(m.values.size() + 1'000 * kDim, 0.25f);  // a block of identical rows
  KMeansOptions options;
  options.clusters = 40;
  const KMeansResult result = kmeans(m.view(), options);
  std::vector<int> members(result.clusters(), 0);
  for (const auto c : result.assignment) ++members[c];
  const auto empty = std::count(members.begin(), members.end(), 0);
  EXPECT_LE(empty, 2);
}

TEST(GroupByCluster, IsAStablePermutationWithOffsets) {
  const std::vector<std::uint32_t> assignment = {2, 0, 2, 1, 0, 2};
  const ClusterOrder order = group_by_cluster(assignment, 4);
  EXPECT_EQ(order.permutation, (std::vector<std::uint32_t>{1, 4, 3, 0, 2, 5}));
  EXPECT_EQ(order.cluster_begin, (std::vector<std::uint32_t>{0, 2, 3, 6, 6}));
  EXPECT_THROW(group_by_cluster(assignment, 2), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Cluster search

TEST(ClusterSearch, ProbingEveryClusterEqualsExactSearch) {
  const Dataset set = blob_dataset(20'000, 40);
  const SortedClusters sorted = sort_by_clusters(set.data, 50);
  const ClusterSearch all = cluster_search(sorted, 50);
  const ExactSearch exact(sorted.rows.view());
  std::vector<float> weights(kDim, 1.0f);
  weights[4] = weights[5] = 0.0f;
  std::vector<Neighbor> expected, found;
  for (std::size_t q = 0; q < set.queries.rows(); ++q) {
    for (const float* w :
         {static_cast<const float*>(nullptr), static_cast<const float*>(weights.data())}) {
      exact.search(set.queries.row(q), w, 20, expected);
      all.search(set.queries.row(q), w, 20, found);
      ASSERT_EQ(found.size(), expected.size());
      for (std::size_t i = 0; i < found.size(); ++i) {
        EXPECT_EQ(found[i].index, expected[i].index);
        EXPECT_EQ(found[i].distance, expected[i].distance);
      }
    }
  }
}

TEST(ClusterSearch, FindsEveryRowItselfWithOneProbe) {
  const Dataset set = blob_dataset(20'000, 0);
  const SortedClusters sorted = sort_by_clusters(set.data, 100);
  EXPECT_GE(self_hit_rate(cluster_search(sorted, 1), sorted.rows, 2'000), 0.999);
  EXPECT_EQ(self_hit_rate(cluster_search(sorted, 4), sorted.rows, 2'000), 1.0);
}

TEST(ClusterSearch, RecallGrowsWithProbes) {
  const Dataset set = blob_dataset(kRecallRows, 200);
  const SortedClusters sorted = sort_by_clusters(set.data, 256);
  const ExactSearch exact(sorted.rows.view());
  const double one = recall(cluster_search(sorted, 1), exact, set.queries, 10);
  const double eight = recall(cluster_search(sorted, 8), exact, set.queries, 10);
  EXPECT_GE(eight, one);
  EXPECT_GE(eight, 0.95);
}

TEST(ClusterSearch, WeightedQueriesFindTheirRow) {
  const Dataset set = blob_dataset(20'000, 0);
  const SortedClusters sorted = sort_by_clusters(set.data, 100);
  const ClusterSearch search = cluster_search(sorted, 8);
  std::vector<float> weights(kDim, 1.0f);
  weights[20] = weights[21] = 0.0f;
  std::vector<Neighbor> out;
  for (std::size_t r = 0; r < sorted.rows.rows(); r += 997) {
    std::vector<float> query(sorted.rows.row(r), sorted.rows.row(r) + kDim);
    query[20] = query[21] = std::numeric_limits<float>::quiet_NaN();
    search.search(query.data(), weights.data(), 1, out);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].index, r);
  }
}

TEST(ClusterSearch, RejectsInconsistentLayouts) {
  const Dataset set = blob_dataset(100, 0);
  const std::vector<float> centroids(2 * kDim, 0.0f);
  const MatrixView c{centroids.data(), 2, kDim};
  const std::vector<std::uint32_t> short_offsets = {0, 100};
  const std::vector<std::uint32_t> wrong_end = {0, 50, 99};
  const std::vector<std::uint32_t> decreasing = {0, 60, 50};
  EXPECT_THROW(ClusterSearch(set.data.view(), c, short_offsets, 1), std::invalid_argument);
  EXPECT_THROW(ClusterSearch(set.data.view(), c, wrong_end, 1), std::invalid_argument);
  EXPECT_THROW(ClusterSearch(set.data.view(), c, decreasing, 1), std::invalid_argument);
  const std::vector<std::uint32_t> good = {0, 50, 100};
  EXPECT_THROW(ClusterSearch(set.data.view(), c, good, 0), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// FLANN

TEST(FlannSearch, KdForestFindsRowsAndReachesRecall) {
  const Dataset set = blob_dataset(kRecallRows, 200);
  FlannOptions options;
  options.checks = 256;
  const FlannSearch flann(set.data.view(), options);
  const ExactSearch exact(set.data.view());
  EXPECT_GE(self_hit_rate(flann, set.data, 2'000), 0.99);
  EXPECT_GE(recall(flann, exact, set.queries, 10), 0.8);
  EXPECT_GT(flann.memory_bytes(), 0u);
}

TEST(FlannSearch, KMeansTreeFindsRowsAndReachesRecall) {
  const Dataset set = blob_dataset(kRecallRows, 200);
  FlannOptions options;
  options.algorithm = FlannAlgorithm::kmeans_tree;
  options.checks = 256;
  const FlannSearch flann(set.data.view(), options);
  const ExactSearch exact(set.data.view());
  EXPECT_GE(self_hit_rate(flann, set.data, 2'000), 0.99);
  EXPECT_GE(recall(flann, exact, set.queries, 10), 0.8);
}

TEST(FlannSearch, RefusesWeights) {
  const Dataset set = blob_dataset(1'000, 1);
  const FlannSearch flann(set.data.view(), {});
  const std::vector<float> weights(kDim, 1.0f);
  std::vector<Neighbor> out;
  EXPECT_FALSE(flann.supports_weights());
  EXPECT_THROW(flann.search(set.queries.row(0), weights.data(), 1, out), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// FAISS

#ifdef MOCAP_HAVE_FAISS
TEST(FaissSearch, FlatEqualsExactSearch) {
  set_faiss_threads(1);
  const Dataset set = blob_dataset(20'000, 30);
  FaissOptions options;
  options.type = FaissIndexType::flat;
  const FaissSearch flat(set.data.view(), options);
  const ExactSearch exact(set.data.view());
  EXPECT_EQ(self_hit_rate(flat, set.data, 1'000), 1.0);
  EXPECT_GE(recall(flat, exact, set.queries, 10), 0.999);
}

TEST(FaissSearch, IvfFindsRowsAndReachesRecall) {
  set_faiss_threads(1);
  const Dataset set = blob_dataset(kRecallRows, 200);
  FaissOptions options;
  options.nlist = 256;
  options.nprobe = 8;
  FaissSearch ivf(set.data.view(), options);
  const ExactSearch exact(set.data.view());
  EXPECT_GE(self_hit_rate(ivf, set.data, 2'000), 0.99);
  const double eight = recall(ivf, exact, set.queries, 10);
  EXPECT_GE(eight, 0.95);
  ivf.set_nprobe(1);
  EXPECT_LE(recall(ivf, exact, set.queries, 10), eight);
}

TEST(FaissSearch, HnswFindsRowsAndReachesRecall) {
  set_faiss_threads(1);
  const Dataset set = blob_dataset(20'000, 200);
  FaissOptions options;
  options.type = FaissIndexType::hnsw_flat;
  options.hnsw_m = 16;
  options.ef_search = 64;
  const FaissSearch hnsw(set.data.view(), options);
  const ExactSearch exact(set.data.view());
  // A greedy graph walk can end in a neighbourhood next to the row's own: HNSW misses a few.
  EXPECT_GE(self_hit_rate(hnsw, set.data, 2'000), 0.97);
  EXPECT_GE(recall(hnsw, exact, set.queries, 10), 0.9);
}

TEST(FaissSearch, RefusesWeights) {
  const Dataset set = blob_dataset(1'000, 1);
  FaissOptions options;
  options.type = FaissIndexType::flat;
  const FaissSearch flat(set.data.view(), options);
  const std::vector<float> weights(kDim, 1.0f);
  std::vector<Neighbor> out;
  EXPECT_THROW(flat.search(set.queries.row(0), weights.data(), 1, out), std::invalid_argument);
}
#endif

// ---------------------------------------------------------------------------------------------
// Edge cases, for every method

// Every method over the same rows, for the checks that must hold for all of them.
struct AllMethods {
  explicit AllMethods(const Matrix& data, int clusters) {
    if (data.rows() > 0) {
      sorted = sort_by_clusters(data, clusters);
    } else {
      sorted.order.cluster_begin = {0};
      sorted.kmeans.dim = kDim;
    }
    rows = data.rows() > 0 ? sorted.rows.view() : MatrixView{nullptr, 0, kDim};
    methods.push_back(std::make_unique<ExactSearch>(rows));
    methods.push_back(std::make_unique<ClusterSearch>(rows, sorted.kmeans.centroid_view(),
                                                      sorted.order.cluster_begin, 2));
    methods.push_back(std::make_unique<FlannSearch>(rows, FlannOptions{}));
    FlannOptions tree;
    tree.algorithm = FlannAlgorithm::kmeans_tree;
    tree.branching = 4;
    methods.push_back(std::make_unique<FlannSearch>(rows, tree));
#ifdef MOCAP_HAVE_FAISS
    for (const auto type :
         {FaissIndexType::flat, FaissIndexType::ivf_flat, FaissIndexType::hnsw_flat}) {
      FaissOptions options;
      options.type = type;
      options.nlist = 4;
      methods.push_back(std::make_unique<FaissSearch>(rows, options));
    }
#endif
  }

  SortedClusters sorted;
  MatrixView rows;
  std::vector<std::unique_ptr<SearchIndex>> methods;
};

TEST(EdgeCases, MoreNeighboursThanRowsReturnsAllRowsSorted) {
  const Dataset set = blob_dataset(30, 1);
  const AllMethods all(set.data, 3);
  std::vector<Neighbor> out;
  for (const auto& method : all.methods) {
    method->search(set.queries.row(0), nullptr, 64, out);
    EXPECT_GE(out.size(), 1u) << method->name();
    EXPECT_LE(out.size(), 30u) << method->name();
    expect_sorted(out);
    std::set<std::uint32_t> unique;
    for (const Neighbor& n : out) unique.insert(n.index);
    EXPECT_EQ(unique.size(), out.size()) << method->name();
  }
  ExactSearch(all.rows).search(set.queries.row(0), nullptr, 64, out);
  EXPECT_EQ(out.size(), 30u);
}

TEST(EdgeCases, ZeroOrNegativeKReturnsNothing) {
  const Dataset set = blob_dataset(100, 1);
  const AllMethods all(set.data, 3);
  std::vector<Neighbor> out = {{1, 1.0f}};
  for (const auto& method : all.methods) {
    for (const int k : {0, -3}) {
      method->search(set.queries.row(0), nullptr, k, out);
      EXPECT_TRUE(out.empty()) << method->name();
      out = {{1, 1.0f}};
    }
  }
}

TEST(EdgeCases, EmptyMatrixReturnsNothing) {
  const Matrix empty;
  const AllMethods all(empty, 3);
  const std::vector<float> query(kDim, 0.0f);
  std::vector<Neighbor> out = {{1, 1.0f}};
  for (const auto& method : all.methods) {
    method->search(query.data(), nullptr, 5, out);
    EXPECT_TRUE(out.empty()) << method->name();
  }
}

TEST(EdgeCases, NamesDescribeTheSettings) {
  const Dataset set = blob_dataset(100, 0);
  const AllMethods all(set.data, 3);
  EXPECT_EQ(all.methods[0]->name(), "exact");
  EXPECT_EQ(all.methods[1]->name(), "clusters(k=3,probe=2)");
  EXPECT_EQ(all.methods[2]->name(), "flann-kd(trees=4,checks=128)");
}

}  // namespace
}  // namespace mocap::posedb
