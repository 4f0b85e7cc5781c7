#include "reconnecting_camera.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace mocap::aravis {

ReconnectingCamera::ReconnectingCamera(CameraSettings settings)
    : settings_(std::move(settings)), camera_(std::make_unique<Camera>(settings_)) {
  id_ = camera_->info().id;
  status_ = "streaming from '" + id_ + "'";
}

ReconnectingCamera::~ReconnectingCamera() = default;

std::string ReconnectingCamera::description() const {
  if (!camera_) return "";
  const Region r = camera_->region();
  std::ostringstream text;
  text << "camera '" << id_ << "' (" << r.width << "x" << r.height << " " << camera_->pixel_format()
       << ", " << camera_->frame_rate() << " fps, " << camera_->buffer_count() << " buffers)";
  return text.str();
}

Poll ReconnectingCamera::poll(std::chrono::milliseconds timeout) {
  if (!camera_) return reconnect();
  Poll poll;
  poll.frame = camera_->next(timeout);
  count_drops(poll);
  if (camera_->control_lost()) return lose(std::move(poll));
  return poll;
}

void ReconnectingCamera::count_drops(Poll& poll) {
  const StreamCounters now = camera_->counters();
  const std::uint64_t drops = now.incomplete + now.skipped_ids;
  if (drops > seen_drops_) poll.new_drops = drops - seen_drops_;
  seen_drops_ = std::max(seen_drops_, drops);
  totals_.incomplete = base_incomplete_ + now.incomplete;
  totals_.skipped = base_skipped_ + now.skipped_ids;
}

Poll ReconnectingCamera::lose(Poll poll) {
  ++totals_.losses;
  poll.news = "camera '" + id_ + "' lost (" + camera_->loss_reason() + "); reconnecting";
  status_ = poll.news + " [" + std::to_string(totals_.losses) + " lost, " +
            std::to_string(totals_.reconnects) + " reconnects]";
  base_incomplete_ = totals_.incomplete;
  base_skipped_ = totals_.skipped;
  seen_drops_ = 0;
  closing_.emplace_back([camera = std::move(camera_)]() mutable { camera.reset(); });
  return poll;
}

Poll ReconnectingCamera::reconnect() {
  Poll poll;
  try {
    camera_ = std::make_unique<Camera>(settings_);
  } catch (const std::runtime_error&) {
    poll.away = true;
    return poll;
  }
  ++totals_.reconnects;
  id_ = camera_->info().id;
  poll.news = "reconnected to " + description();
  status_ = "reconnected to camera '" + id_ + "' [" + std::to_string(totals_.losses) + " lost, " +
            std::to_string(totals_.reconnects) + " reconnects]";
  return poll;
}

}  // namespace mocap::aravis
