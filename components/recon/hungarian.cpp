#include "recon/hungarian.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mocap::recon {

void AssignmentSolver::solve(std::span<const float> cost, int rows, int cols,
                             std::span<int> row_to_col) {
  if (rows < 0 || cols < 0 || cost.size() != static_cast<std::size_t>(rows) * cols ||
      row_to_col.size() != static_cast<std::size_t>(rows)) {
    throw std::invalid_argument("AssignmentSolver: matrix or result size does not match");
  }
  if (!std::all_of(cost.begin(), cost.end(), [](float c) { return std::isfinite(c); })) {
    throw std::invalid_argument("AssignmentSolver: costs must be finite");
  }
  std::fill(row_to_col.begin(), row_to_col.end(), -1);
  if (rows == 0 || cols == 0) return;
  // The method assigns every row of a matrix with at least as many columns as rows; a tall
  // matrix is read transposed through the strides instead of being copied.
  const bool wide = rows <= cols;
  if (wide) {
    solve_wide(cost.data(), rows, cols, cols, 1);
  } else {
    solve_wide(cost.data(), cols, rows, 1, cols);
  }
  const int wide_cols = wide ? cols : rows;
  for (int c = 1; c <= wide_cols; ++c) {
    const int owner = col_owner_[c] - 1;
    if (owner < 0) continue;
    if (wide) {
      row_to_col[owner] = c - 1;
    } else {
      row_to_col[c - 1] = owner;
    }
  }
}

// Adds the rows one at a time; each addition finds the cheapest augmenting path from the new row
// to a free column (Dijkstra on reduced costs, which the potentials keep non-negative) and flips
// the assignment along it. Indices are 1-based; column 0 is the new row's virtual start.
void AssignmentSolver::solve_wide(const float* cost, int rows, int cols, int row_stride,
                                  int col_stride) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  const auto n = static_cast<std::size_t>(cols) + 1;
  row_potential_.assign(static_cast<std::size_t>(rows) + 1, 0.0);
  col_potential_.assign(n, 0.0);
  col_owner_.assign(n, 0);
  previous_col_.assign(n, 0);
  for (int row = 1; row <= rows; ++row) {
    col_owner_[0] = row;
    int col = 0;
    min_slack_.assign(n, kInfinity);
    visited_.assign(n, 0);
    do {
      visited_[col] = 1;
      const int owner = col_owner_[col];
      const float* owner_costs = cost + static_cast<std::size_t>(owner - 1) * row_stride;
      double delta = kInfinity;
      int next_col = 0;
      for (int c = 1; c <= cols; ++c) {
        if (visited_[c]) continue;
        const double reduced = owner_costs[static_cast<std::size_t>(c - 1) * col_stride] -
                               row_potential_[owner] - col_potential_[c];
        if (reduced < min_slack_[c]) {
          min_slack_[c] = reduced;
          previous_col_[c] = col;
        }
        if (min_slack_[c] < delta) {  // strict: the lowest column wins a tie
          delta = min_slack_[c];
          next_col = c;
        }
      }
      for (int c = 0; c <= cols; ++c) {
        if (visited_[c]) {
          row_potential_[col_owner_[c]] += delta;
          col_potential_[c] -= delta;
        } else {
          min_slack_[c] -= delta;
        }
      }
      col = next_col;
    } while (col_owner_[col] != 0);
    do {  // flip the path back to the virtual start
      const int previous = previous_col_[col];
      col_owner_[col] = col_owner_[previous];
      col = previous;
    } while (col != 0);
  }
}

}  // namespace mocap::recon
