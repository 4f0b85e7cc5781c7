#pragma once
// Optimal assignment (the Hungarian method, in its shortest-augmenting-path form with dual
// potentials, O(n²·m)): given a rows × cols cost matrix, pair rows with columns, each used at most
// once, as many pairs as min(rows, cols), with the least total cost. The tracker's per-frame
// association; a few tens of people take microseconds.

#include <span>
#include <vector>

namespace mocap::recon {

class AssignmentSolver {
 public:
  // `cost` is row-major, rows × cols, finite. On return row_to_col[r] is the column given to row r,
  // or −1 when rows > cols and row r got none. row_to_col must hold `rows` entries. Forbidden
  // pairs should get a large finite cost (and be dropped by the caller afterwards): the result
  // then has the fewest forbidden pairs, and the least cost among those. Reuses its buffers, so it
  // allocates nothing once it has seen the largest problem. Ties are broken deterministically.
  void solve(std::span<const float> cost, int rows, int cols, std::span<int> row_to_col);

 private:
  void solve_wide(const float* cost, int rows, int cols, int row_stride, int col_stride);

  std::vector<double> row_potential_;
  std::vector<double> col_potential_;
  std::vector<double> min_slack_;
  std::vector<int> col_owner_;  // 1-based row owning each column, 0 = free; entry 0 is a sentinel
  std::vector<int> previous_col_;
  std::vector<char> visited_;
};

}  // namespace mocap::recon
