// The assignment solver against brute force over every pairing, on square, wide and tall matrices.

#include "recon/hungarian.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace mocap::recon {
namespace {

// Least total cost over all ways of pairing min(rows, cols) rows with distinct columns.
double brute_force_cost(const std::vector<float>& cost, int rows, int cols) {
  const bool wide = rows <= cols;
  const int small = wide ? rows : cols;
  const int large = wide ? cols : rows;
  std::vector<int> order(large);
  std::iota(order.begin(), order.end(), 0);
  double best = std::numeric_limits<double>::infinity();
  do {  // the first `small` entries of each permutation pick the partners
    double total = 0.0;
    for (int i = 0; i < small; ++i) {
      total += wide ? cost[i * cols + order[i]] : cost[order[i] * cols + i];
    }
    best = std::min(best, total);
  } while (std::next_permutation(order.begin(), order.end()));
  return best;
}

double assigned_cost(const std::vector<float>& cost, int cols, const std::vector<int>& row_to_col) {
  double total = 0.0;
  for (std::size_t r = 0; r < row_to_col.size(); ++r) {
    if (row_to_col[r] >= 0) total += cost[r * cols + row_to_col[r]];
  }
  return total;
}

void expect_valid(const std::vector<int>& row_to_col, int rows, int cols) {
  std::vector<int> used(cols, 0);
  int assigned = 0;
  for (int c : row_to_col) {
    if (c < 0) continue;
    ASSERT_LT(c, cols);
    EXPECT_EQ(used[c]++, 0) << "column " << c << " given twice";
    ++assigned;
  }
  EXPECT_EQ(assigned, std::min(rows, cols));
  EXPECT_EQ(static_cast<int>(row_to_col.size()), rows);
}

TEST(AssignmentSolver, HandExample) {
  // Greedy would take the 1 (row 0 → col 0) and then pay 9; the optimum pays 2 + 3.
  const std::vector<float> cost = {1, 2,  //
                                   3, 9};
  AssignmentSolver solver;
  std::vector<int> row_to_col(2);
  solver.solve(cost, 2, 2, row_to_col);
  EXPECT_EQ(row_to_col, (std::vector<int>{1, 0}));
}

TEST(AssignmentSolver, MatchesBruteForce) {
  std::mt19937 rng(123);
  std::uniform_real_distribution<float> u(0.0f, 10.0f);
  AssignmentSolver solver;  // one solver for all sizes: buffers are reused
  for (int rows = 1; rows <= 6; ++rows) {
    for (int cols = 1; cols <= 6; ++cols) {
      for (int trial = 0; trial < 20; ++trial) {
        std::vector<float> cost(rows * cols);
        for (float& c : cost) c = trial % 4 == 0 ? std::round(u(rng) / 3.0f) : u(rng);  // ties too
        std::vector<int> row_to_col(rows);
        solver.solve(cost, rows, cols, row_to_col);
        expect_valid(row_to_col, rows, cols);
        EXPECT_NEAR(assigned_cost(cost, cols, row_to_col), brute_force_cost(cost, rows, cols), 1e-4)
            << rows << "x" << cols << " trial " << trial;
      }
    }
  }
}

// Forbidden pairs carry a large cost: the solver takes as many allowed pairs as possible.
TEST(AssignmentSolver, LargeCostsAreAvoidedWhenPossible) {
  constexpr float kBig = 1e6f;
  const std::vector<float> cost = {0.1f, kBig, kBig,  //
                                   0.2f, 0.9f, kBig,  //
                                   kBig, kBig, 0.3f};
  AssignmentSolver solver;
  std::vector<int> row_to_col(3);
  solver.solve(cost, 3, 3, row_to_col);
  EXPECT_EQ(row_to_col, (std::vector<int>{0, 1, 2}));
}

TEST(AssignmentSolver, EmptyAndBadInput) {
  AssignmentSolver solver;
  std::vector<int> none;
  solver.solve({}, 0, 3, none);
  std::vector<int> three(3, 7);
  solver.solve({}, 3, 0, three);
  EXPECT_EQ(three, (std::vector<int>{-1, -1, -1}));
  std::vector<int> one(1);
  const std::vector<float> nan_cost = {NAN};
  EXPECT_THROW(solver.solve(nan_cost, 1, 1, one), std::invalid_argument);
  const std::vector<float> short_cost = {1.0f};
  EXPECT_THROW(solver.solve(short_cost, 1, 2, one), std::invalid_argument);
}

TEST(AssignmentSolver, Deterministic) {
  const std::vector<float> cost(16, 1.0f);  // every pairing ties
  AssignmentSolver a, b;
  std::vector<int> first(4), second(4);
  a.solve(cost, 4, 4, first);
  b.solve(cost, 4, 4, second);
  EXPECT_EQ(first, second);
  expect_valid(first, 4, 4);
}

}  // namespace
}  // namespace mocap::recon
