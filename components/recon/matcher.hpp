#pragma once
// The matcher: a person's 2D body in, the k nearest database projections out. Joints that are
// missing or of low confidence are left out of the distance (the paper's future work), so a
// person with a hidden arm or cut off at the knees still finds full-body candidates.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/body15.hpp"
#include "posedb/database.hpp"

namespace mocap::recon {

struct MatchOptions {
  int k = 32;          // candidates per person
  int probe = 16;      // clusters scanned (see the search benchmark in the issue-2 report)
  bool exact = false;  // scan every projection instead (slow; for evaluation)
  float min_confidence = 0.05f;  // joints below are treated as missing
  int min_joints = 6;            // fewer present joints: no match
  int rescale_passes = 2;        // for partial bodies, see Matcher::match
};

struct Candidate {
  std::uint32_t projection = 0;  // row in the database's projections
  std::uint32_t frame = 0;       // database frame
  std::uint32_t view = 0;
  float distance = 0.0f;  // weighted squared distance over the present joints
};

class Matcher {
 public:
  Matcher(const posedb::Database& db, const MatchOptions& options);
  ~Matcher();
  Matcher(Matcher&&) noexcept;

  // `body_xyc`: 15 joints (x, y, confidence) in image coordinates, y down. Returns false when the
  // pose cannot be matched (root missing, too few joints). `out` is reused between calls.
  bool match(std::span<const float, kBodyJoints * 3> body_xyc, std::vector<Candidate>& out);

  const MatchOptions& options() const { return options_; }
  const posedb::Database& database() const { return db_; }

 private:
  const posedb::Database& db_;
  MatchOptions options_;
  struct Search;
  std::unique_ptr<Search> search_;
};

}  // namespace mocap::recon
