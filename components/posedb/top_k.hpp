#pragma once
// Keeps the k best candidates of a stream in a bounded max-heap that lives in the caller's result
// vector, so a search allocates nothing once that vector has grown to k.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "posedb/search.hpp"

namespace mocap::posedb {

// A strict total order: equal distances are broken by index, so every method and every scan
// order returns the same neighbours for the same distances.
inline bool closer(const Neighbor& a, const Neighbor& b) {
  return a.distance < b.distance || (a.distance == b.distance && a.index < b.index);
}

class TopK {
 public:
  TopK(std::vector<Neighbor>& storage, std::size_t k) : heap_(storage), k_(k) {
    heap_.clear();
    heap_.reserve(k);
  }

  // Candidates farther than this can be skipped without calling offer().
  float bound() const {
    if (heap_.size() < k_) return std::numeric_limits<float>::infinity();
    return k_ == 0 ? -std::numeric_limits<float>::infinity() : heap_.front().distance;
  }

  void offer(std::uint32_t index, float distance) {
    const Neighbor candidate{index, distance};
    if (heap_.size() < k_) {
      heap_.push_back(candidate);
      std::push_heap(heap_.begin(), heap_.end(), closer);
    } else if (k_ > 0 && closer(candidate, heap_.front())) {
      std::pop_heap(heap_.begin(), heap_.end(), closer);
      heap_.back() = candidate;
      std::push_heap(heap_.begin(), heap_.end(), closer);
    }
  }

  // Leaves the storage sorted by increasing distance; the TopK must not be used afterwards.
  void finish() { std::sort_heap(heap_.begin(), heap_.end(), closer); }

 private:
  std::vector<Neighbor>& heap_;
  std::size_t k_;
};

}  // namespace mocap::posedb
