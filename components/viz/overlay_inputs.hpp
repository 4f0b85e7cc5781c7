#pragma once
// Joins the overlay's inputs by frame number. The 2D people, the 3D people and the video frames
// arrive on separate ports, one message at a time and in no fixed interleaving, but each stream
// in frame order; a frame can be drawn once its parts are all there.

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "core/messages.hpp"

namespace mocap::viz {

struct OverlayFrame {
  std::int64_t frame = 0;
  std::shared_ptr<const People2D> people2d;
  std::shared_ptr<const People3D> people3d;
  std::shared_ptr<const VideoFrame> video;  // may stay empty
};

class OverlayInputs {
 public:
  // Keeps at most `max_pending` incomplete frames (the oldest go first, counted as dropped).
  // `wait_for_video`: a frame also waits for its video frame; otherwise it is drawn as soon as
  // its 2D and 3D people are there, on the video frame when that came first.
  OverlayInputs(std::size_t max_pending, bool wait_for_video);

  void add(std::shared_ptr<const People2D> people);
  void add(std::shared_ptr<const People3D> people);
  void add(std::shared_ptr<const VideoFrame> video);

  // Frames ready to draw, oldest first. Since each stream comes in order, an unfinished frame
  // older than a ready one never completes: it is dropped.
  std::vector<OverlayFrame> take_ready();
  // At the end of the streams: every frame with 2D and 3D people (video or not), oldest first;
  // the rest are dropped.
  std::vector<OverlayFrame> take_remaining();

  // Frames with 2D or 3D people that were never drawn. Video frames no people came for (the
  // detector skipped them) are let go without counting.
  std::int64_t dropped() const { return dropped_; }
  std::size_t pending() const { return pending_.size(); }

 private:
  OverlayFrame& slot(std::int64_t frame);
  bool ready(const OverlayFrame& f) const;
  void drop(const OverlayFrame& f);

  std::size_t max_pending_;
  bool wait_for_video_;
  std::map<std::int64_t, OverlayFrame> pending_;
  std::int64_t dropped_ = 0;
};

}  // namespace mocap::viz
