#include "multiview/association.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace mocap::multiview {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

std::uint64_t bit(int view) { return std::uint64_t{1} << view; }

}  // namespace

int ViewClustering::support(const Pair& pair, float gate) const {
  const int va = (*table_)[candidates_[pair.a]].view, vb = (*table_)[candidates_[pair.b]].view;
  std::uint64_t confirming = 0;
  for (std::size_t k = 0; k < n_; ++k) {
    const int vk = (*table_)[candidates_[k]].view;
    if (vk == va || vk == vb) continue;
    if (cost(pair.a, static_cast<int>(k)) <= gate && cost(pair.b, static_cast<int>(k)) <= gate) {
      confirming |= bit(vk);
    }
  }
  return std::popcount(confirming);
}

void ViewClustering::grow(std::uint64_t& views, float gate) {
  for (;;) {
    int best = -1;
    float best_link = gate;
    for (std::size_t k = 0; k < n_; ++k) {
      if (group_of_[k] >= 0 || (views & bit((*table_)[candidates_[k]].view))) continue;
      // Complete linkage over the comparable pairs: the worst agreement must pass the gate.
      float link = -1.0f;
      for (const int m : members_) {
        const float c = cost(static_cast<int>(k), m);
        if (std::isnan(c)) continue;
        link = std::max(link, c);
      }
      if (link >= 0.0f && link <= best_link) {
        best = static_cast<int>(k);
        best_link = link;
      }
    }
    if (best < 0) return;
    group_of_[static_cast<std::size_t>(best)] = group_of_[static_cast<std::size_t>(members_[0])];
    members_.push_back(best);
    views |= bit((*table_)[candidates_[static_cast<std::size_t>(best)]].view);
  }
}

void ViewClustering::cluster(const DetectionTable& table, std::span<const int> candidates,
                             const RayCostOptions& costs, float pair_gate_m) {
  table_ = &table;
  candidates_.assign(candidates.begin(), candidates.end());
  n_ = candidates_.size();
  cost_.assign(n_ * n_, kNaN);
  pairs_.clear();
  for (std::size_t a = 0; a < n_; ++a) {
    for (std::size_t b = a + 1; b < n_; ++b) {
      if (table[candidates_[a]].view == table[candidates_[b]].view) continue;
      const float c = table.pair_cost(candidates_[a], candidates_[b], costs);
      cost_[a * n_ + b] = cost_[b * n_ + a] = c;
      if (c <= pair_gate_m) pairs_.push_back({static_cast<int>(a), static_cast<int>(b), 0, c});
    }
  }
  for (Pair& p : pairs_) p.support = support(p, pair_gate_m);
  std::sort(pairs_.begin(), pairs_.end(), [](const Pair& x, const Pair& y) {
    if (x.support != y.support) return x.support > y.support;
    if (x.cost != y.cost) return x.cost < y.cost;
    return x.a != y.a ? x.a < y.a : x.b < y.b;  // deterministic order on ties
  });

  group_of_.assign(n_, -1);
  group_members_.clear();
  group_start_.assign(1, 0);
  for (const Pair& p : pairs_) {
    if (group_of_[p.a] >= 0 || group_of_[p.b] >= 0) continue;
    const int g = groups();
    group_of_[p.a] = group_of_[p.b] = g;
    members_.assign({p.a, p.b});
    std::uint64_t views = bit(table[candidates_[p.a]].view) | bit(table[candidates_[p.b]].view);
    grow(views, pair_gate_m);
    for (const int m : members_) group_members_.push_back(candidates_[m]);
    group_start_.push_back(static_cast<int>(group_members_.size()));
  }
}

std::span<const int> ViewClustering::group(int g) const {
  return std::span<const int>(group_members_)
      .subspan(static_cast<std::size_t>(group_start_[g]),
               static_cast<std::size_t>(group_start_[g + 1] - group_start_[g]));
}

}  // namespace mocap::multiview
