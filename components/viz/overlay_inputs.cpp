#include "viz/overlay_inputs.hpp"

#include <stdexcept>

namespace mocap::viz {

OverlayInputs::OverlayInputs(std::size_t max_pending, bool wait_for_video)
    : max_pending_(max_pending), wait_for_video_(wait_for_video) {
  if (max_pending_ < 1) throw std::invalid_argument("overlay: max_pending must be at least 1");
}

OverlayFrame& OverlayInputs::slot(std::int64_t frame) {
  auto [it, added] = pending_.try_emplace(frame);
  it->second.frame = frame;
  while (pending_.size() > max_pending_) {
    auto oldest = pending_.begin();
    if (oldest == it) break;  // the newest arrival is never the one let go
    drop(oldest->second);
    pending_.erase(oldest);
  }
  return it->second;
}

void OverlayInputs::add(std::shared_ptr<const People2D> people) {
  OverlayFrame& f = slot(people->header.frame);
  if (!f.people2d) f.people2d = std::move(people);
}

void OverlayInputs::add(std::shared_ptr<const People3D> people) {
  OverlayFrame& f = slot(people->header.frame);
  if (!f.people3d) f.people3d = std::move(people);
}

void OverlayInputs::add(std::shared_ptr<const VideoFrame> video) {
  OverlayFrame& f = slot(video->header.frame);
  if (!f.video) f.video = std::move(video);
}

bool OverlayInputs::ready(const OverlayFrame& f) const {
  return f.people2d && f.people3d && (f.video || !wait_for_video_);
}

void OverlayInputs::drop(const OverlayFrame& f) {
  if (f.people2d || f.people3d) ++dropped_;
}

std::vector<OverlayFrame> OverlayInputs::take_ready() {
  auto newest_ready = pending_.end();
  for (auto it = pending_.begin(); it != pending_.end(); ++it) {
    if (ready(it->second)) newest_ready = it;
  }
  std::vector<OverlayFrame> out;
  if (newest_ready == pending_.end()) return out;
  const auto end = std::next(newest_ready);
  for (auto it = pending_.begin(); it != end; ++it) {
    if (ready(it->second)) {
      out.push_back(std::move(it->second));
    } else {
      drop(it->second);
    }
  }
  pending_.erase(pending_.begin(), end);
  return out;
}

std::vector<OverlayFrame> OverlayInputs::take_remaining() {
  std::vector<OverlayFrame> out;
  for (auto& [frame, f] : pending_) {
    if (f.people2d && f.people3d) {
      out.push_back(std::move(f));
    } else {
      drop(f);
    }
  }
  pending_.clear();
  return out;
}

}  // namespace mocap::viz
