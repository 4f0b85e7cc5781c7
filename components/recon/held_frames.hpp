#pragma once
// The single-input lag buffer of the nodes that decide each person of a frame at its own time
// (recon.temporal_selector: a path with a lag per person; recon.fit: a fixed lag or a window per
// person): every frame is held until every person in it is decided, then frames leave oldest
// first, so a stream keeps one output per input frame, in input order, while the people in it are
// decided late and out of step with each other.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>
#include <vector>

namespace mocap::recon {

template <class Frame>
class HeldFrames {
 public:
  // Holds `frame` until each person of `waiting_for` (ids) is decided in it; returns its index:
  // 0, 1, 2, ... in the order frames are held.
  std::int64_t hold(Frame frame, std::vector<int> waiting_for) {
    std::sort(waiting_for.begin(), waiting_for.end());
    waiting_for.erase(std::unique(waiting_for.begin(), waiting_for.end()), waiting_for.end());
    frames_.push_back({std::move(frame), std::move(waiting_for)});
    return next_index() - 1;
  }

  // Frame `index` while it is held; nullptr once it has left (or was never held).
  Frame* find(std::int64_t index) {
    if (index < first_ || index >= next_index()) return nullptr;
    return &frames_[static_cast<std::size_t>(index - first_)].frame;
  }

  // Person `id` is decided in frame `index`. False when the frame has left or did not wait for
  // them (a person absent from it, or decided already).
  bool decide(std::int64_t index, int id) {
    if (index < first_ || index >= next_index()) return false;
    auto& waiting = frames_[static_cast<std::size_t>(index - first_)].waiting;
    const auto it = std::lower_bound(waiting.begin(), waiting.end(), id);
    if (it == waiting.end() || *it != id) return false;
    waiting.erase(it);
    return true;
  }

  // Frames leave, oldest first, while the oldest has every person decided: `release(Frame&&)`
  // is called for each. Returns how many left.
  template <class Release>
  std::size_t release_decided(Release&& release) {
    std::size_t n = 0;
    while (!frames_.empty() && frames_.front().waiting.empty()) pop(release), ++n;
    return n;
  }

  // Every held frame leaves, decided or not (the end of the stream).
  template <class Release>
  std::size_t release_all(Release&& release) {
    const std::size_t n = frames_.size();
    while (!frames_.empty()) pop(release);
    return n;
  }

  std::size_t size() const { return frames_.size(); }
  bool empty() const { return frames_.empty(); }
  // The index the next held frame gets.
  std::int64_t next_index() const { return first_ + static_cast<std::int64_t>(frames_.size()); }

 private:
  struct Held {
    Frame frame;
    std::vector<int> waiting;  // sorted ids not decided yet
  };

  template <class Release>
  void pop(Release& release) {
    Frame frame = std::move(frames_.front().frame);
    frames_.pop_front();
    ++first_;
    release(std::move(frame));
  }

  std::deque<Held> frames_;
  std::int64_t first_ = 0;  // index of frames_.front()
};

}  // namespace mocap::recon
