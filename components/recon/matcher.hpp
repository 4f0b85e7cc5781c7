#pragma once
// The matcher: a person's 2D body in, the k nearest database projections out. Joints that are
// missing or of low confidence are left out of the distance (the paper's future work), so a
// person with a hidden arm or cut off at the knees still finds full-body candidates.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/body15.hpp"
#include "core/messages.hpp"
#include "motion/canonical_body.hpp"
#include "posedb/database.hpp"
#include "recon/layout_offsets.hpp"

namespace mocap::recon {

struct ScalerOptions {
  float min_confidence = 0.05f;  // joints below are treated as missing
  int min_joints = 6;            // fewer present joints: no match
};

// The scaler: the database's normalisation applied to a person's 15 body joints (x, y,
// confidence in image pixels). Missing joints come out as NaN. False when the pose cannot be
// normalised (root missing, too few joints).
bool normalize_body(std::span<const float, kBodyJoints * 3> body_xyc, posedb::Scaling scaling,
                    const ScalerOptions& options, posedb::PoseVector& out);

struct MatchOptions {
  int k = 32;              // candidates per person
  int probe = 16;          // clusters scanned (see the search benchmark in the issue-2 report)
  bool exact = false;      // scan every projection instead (slow; for evaluation)
  int rescale_passes = 2;  // for partial bodies, see Matcher::search
  ScalerOptions scaler;
};

// A database projection near a query: projection row, database frame and view, distance.
using Candidate = PoseCandidate;

class Matcher {
 public:
  Matcher(const posedb::Database& db, const MatchOptions& options);
  ~Matcher();
  Matcher(Matcher&&) noexcept;

  // The k nearest projections of a normalised pose (NaN = missing joint, left out of the
  // distance). `out` is reused between calls.
  void search(const posedb::PoseVector& query, std::vector<Candidate>& out);
  // Scaler and search in one: `body_xyc` is 15 joints (x, y, confidence) in image pixels, y down.
  // Returns false when the pose cannot be normalised.
  bool match(std::span<const float, kBodyJoints * 3> body_xyc, std::vector<Candidate>& out);

  // The person's own proportions, when known (fitted, or given in an evaluation): the k
  // candidates are then re-scored on them (each candidate's 3D pose retargeted to the person,
  // projected with its view, normalised and compared with the query again) and re-sorted.
  // std::nullopt (the default) compares on the database's body as stored.
  void set_person(std::optional<motion::BodyProportions> person) { person_ = std::move(person); }
  const std::optional<motion::BodyProportions>& person() const { return person_; }

  // The layout the 2D input is in, when its keypoints are not the canonical joints
  // (docs/keypoint-layouts.md). match() then searches with the input moved onto the canonical
  // joints (apply_layout_offsets, 2D) and as it is, and re-scores the candidates of both (the
  // best k are kept) the other way round: each
  // candidate's canonical 3D joints (retargeted to the person when set) are moved into the
  // layout's definition with the full 3D offsets (forward included,
  // apply_layout_offsets_3d(-1)), projected with its view, normalised and compared with the
  // input as it is. The input given to match() must then be the uncorrected keypoints.
  void set_layout(std::optional<LayoutOffsets> layout) { layout_ = std::move(layout); }
  const std::optional<LayoutOffsets>& layout() const { return layout_; }

  const MatchOptions& options() const { return options_; }
  const posedb::Database& database() const { return db_; }

 private:
  const posedb::Database& db_;
  MatchOptions options_;
  std::optional<motion::BodyProportions> person_;
  std::optional<LayoutOffsets> layout_;
  std::vector<Candidate> uncorrected_;  // match() with a layout: the uncorrected input's search
  struct Search;
  // Re-scores `out` against `query` (person_, layout_) and re-sorts it.
  void rescore(const posedb::PoseVector& query, std::vector<Candidate>& out) const;
  std::unique_ptr<Search> search_;
};

}  // namespace mocap::recon
