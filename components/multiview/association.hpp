#pragma once
// Which detections in which views are one person, from geometry alone, when no track predicts
// them (the first frame, a person entering, a track lost): the clustering of the cold start.
//
// 1. Every pair of detections in different views gets its ray cost (detections.hpp: the mean
//    distance between the rays of their keypoints, metres). Pairs within `pair_gate_m` are
//    candidates.
// 2. Each candidate pair counts the other views that hold a detection agreeing with *both* of its
//    detections (a closed triangle of candidate pairs): a true pair is confirmed by every view that
//    sees the person, a pair of two people whose rays happen to cross (people lined up between two
//    cameras) by few or none. This is the cycle consistency of the multi-view matching methods
//    (MVPose, 4D Association, EasyMocap) in its greedy form.
// 3. Pairs are taken best supported first (then cheapest); a pair of two free detections starts a
//    person, which then grows view by view with the free detection whose largest cost to the
//    person's detections is smallest, while that stays within the gate (complete linkage): one
//    detection per view, and every detection agrees with every other, so the groups are
//    consistent over all views by construction.
//
// The caller triangulates each group, throws out detections that do not fit the 3D person and
// offers the leftovers to every person (reconstructor.hpp).

#include <cstdint>
#include <span>
#include <vector>

#include "multiview/detections.hpp"

namespace mocap::multiview {

class ViewClustering {
 public:
  // Groups the detections `candidates` (indices into `table`) into people of two views or more.
  // groups() lists the groups; a candidate in none is in no group.
  void cluster(const DetectionTable& table, std::span<const int> candidates,
               const RayCostOptions& costs, float pair_gate_m);

  int groups() const { return static_cast<int>(group_start_.size()) - 1; }
  // The table indices of group g, one per view.
  std::span<const int> group(int g) const;

 private:
  struct Pair {
    int a = 0, b = 0;  // positions in candidates_
    int support = 0;
    float cost = 0.0f;
  };

  float cost(int a, int b) const { return cost_[static_cast<std::size_t>(a) * n_ + b]; }
  int support(const Pair& pair, float gate) const;
  void grow(std::uint64_t& views, float gate);

  const DetectionTable* table_ = nullptr;
  std::size_t n_ = 0;
  std::vector<int> candidates_;
  std::vector<float> cost_;  // n × n, NaN: not comparable
  std::vector<Pair> pairs_;
  std::vector<int> group_of_;       // per candidate, -1: none
  std::vector<int> members_;        // of the group being grown (positions in candidates_)
  std::vector<int> group_members_;  // table indices, group after group
  std::vector<int> group_start_;
};

}  // namespace mocap::multiview
