#include "video/playback.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <sstream>
#include <utility>

namespace mocap::video {
namespace {

std::int64_t realtime_now_ns() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

}  // namespace

Playback::Playback(std::string path, SourceOptions source_options, PlaybackOptions options)
    : path_(std::move(path)),
      source_options_(source_options),
      source_(path_, source_options_),
      live_(options.live.value_or(source_.live())),
      paced_(live_ && !source_.live()),
      loop_(options.loop && !source_.live()),
      frame_offset_(options.frame_offset),
      reconnect_ms_(options.reconnect_ms),
      replay_fps_(options.replay_fps) {}

std::string Playback::describe() const {
  std::ostringstream text;
  text << name(source_.kind()) << " " << path_ << ", " << source_.width() << "x" << source_.height()
       << ", " << source_.fps() << " fps, ";
  if (source_.frame_count() >= 0)
    text << source_.frame_count();
  else
    text << "unknown";
  text << " frames, " << (live_ ? "live" : "offline");
  if (paced_ && replay_fps_ > 0) text << " replayed at " << replay_fps_ << " fps";
  if (source_options_.decoder_threads > 0 && !decoder_threads_supported())
    text << " (decoder_threads ignored: this OpenCV's FFmpeg backend decodes with one thread per "
            "core; OpenCV 4.7 can set it)";
  return text.str();
}

std::string Playback::describe_losses() const {
  std::string text = std::to_string(late_) + " skipped (late), " + std::to_string(undecodable_) +
                     " corrupt frames skipped";
  if (loop_) text += ", started again " + std::to_string(passes_) + " times";
  if (losses_ > 0)
    text += ", stream lost " + std::to_string(losses_) + " times, back " +
            std::to_string(reconnects_) + " times";
  return text;
}

double Playback::frame_period_s() const {
  return source_.fps() > 0 ? 1.0 / source_.fps() : 1.0 / 30.0;
}

double Playback::pace_period_s() const {
  return replay_fps_ > 0 ? 1.0 / replay_fps_ : frame_period_s();
}

std::optional<StampedFrame> Playback::next(const WaitUntil& wait) {
  if (reconnecting() && !reconnect(wait)) return std::nullopt;
  for (;;) {
    std::optional<Frame> frame = paced_ ? paced_read(wait) : source_.read();
    if (frame) {
      frame->index += index_base_;
      last_media_time_s_ = frame->media_time_s;
      std::int64_t stamp =
          live_ ? frame->capture_ns : std::llround((pass_offset_s_ + frame->media_time_s) * 1e9);
      if (frame_offset_ != 0) {
        frame->index += frame_offset_;
        if (source_.fps() > 0) stamp += std::llround(1e9 * frame_offset_ / source_.fps());
      }
      return StampedFrame{std::move(*frame), stamp};
    }
    if (stopped_) return std::nullopt;  // a paced wait cut short: not the end
    if (may_reconnect()) {
      lose_stream();
      return std::nullopt;
    }
    if (const auto undecodable = source_.frames_undecodable(); undecodable > 0) {
      undecodable_ += static_cast<std::uint64_t>(undecodable);
      add_news(std::to_string(undecodable) + " corrupt frames skipped in " + source_.source() +
               " (" + std::to_string(undecodable_) + " so far)");
    }
    if (!start_next_pass()) return std::nullopt;
  }
}

bool Playback::start_next_pass() {
  if (!loop_ || source_.frames_read() == 0) return false;
  pass_offset_s_ += last_media_time_s_ + frame_period_s();
  source_ = VideoSource(path_, source_options_);
  pace_start_ns_ = 0;
  ++passes_;
  return true;
}

// A live stream of no announced length has no end: its stop is a loss.
bool Playback::may_reconnect() const {
  return live_ && reconnect_ms_ > 0 && source_.kind() == SourceKind::network &&
         source_.frame_count() < 0;
}

void Playback::lose_stream() {
  const std::int64_t now = realtime_now_ns();
  lost_since_ns_ = now;
  next_attempt_ns_ = now;  // at once: a server restarted answers right away
  attempts_ = 0;
  ++losses_;
  index_base_ += source_.frames_read();
  add_news("lost " + path_ + " after " + std::to_string(index_base_) +
           " frames (the server went away, the network is down, or the stream ended); opening it "
           "again every " +
           std::to_string(reconnect_ms_) + " ms until it answers");
}

bool Playback::reconnect(const WaitUntil& wait) {
  if (next_attempt_ns_ > realtime_now_ns() && !wait(next_attempt_ns_)) {
    stopped_ = true;
    return false;
  }
  ++attempts_;
  next_attempt_ns_ = realtime_now_ns() + std::int64_t{reconnect_ms_} * 1'000'000;
  try {
    source_ = VideoSource(path_, source_options_);
  } catch (const std::exception&) {
    return false;  // not back yet (the reason was given when it was lost)
  }
  const double away_s = static_cast<double>(realtime_now_ns() - lost_since_ns_) * 1e-9;
  std::ostringstream text;
  text.precision(3);
  text << path_ << " is back after " << away_s << " s (" << attempts_ << " attempts)";
  add_news(text.str());
  lost_since_ns_ = 0;
  ++reconnects_;
  return true;
}

void Playback::add_news(const std::string& text) {
  if (!news_.empty()) news_ += "; ";
  news_ += text;
}

std::string Playback::take_news() { return std::exchange(news_, std::string()); }

std::uint64_t Playback::take_drops() {
  const std::uint64_t passed_over = late_ + undecodable_;
  return passed_over - std::exchange(drops_taken_, passed_over);
}

std::string Playback::status() const {
  if (reconnecting()) return "lost, reconnecting";
  if (undecodable_ > 0) return std::to_string(undecodable_) + " corrupt frames skipped";
  if (reconnects_ > 0) return "reconnected";
  if (passes_ > 0) return "started again " + std::to_string(passes_) + " times";
  return {};
}

std::optional<Frame> Playback::paced_read(const WaitUntil& wait) {
  if (pace_start_ns_ == 0) pace_start_ns_ = realtime_now_ns();
  const double period = pace_period_s();
  for (;;) {
    const double due_s = static_cast<double>(source_.frames_read()) * period;
    const double late_s = static_cast<double>(realtime_now_ns() - pace_start_ns_) * 1e-9 - due_s;
    if (late_s < period) break;
    if (!source_.skip()) return std::nullopt;
    ++late_;
  }
  const std::int64_t due_ns =
      pace_start_ns_ + std::llround(1e9 * static_cast<double>(source_.frames_read()) * period);
  if (due_ns > realtime_now_ns() && !wait(due_ns)) {
    stopped_ = true;
    return std::nullopt;
  }
  std::optional<Frame> frame = source_.read();
  if (frame) frame->capture_ns = due_ns;  // captured when due: latency is measured from here
  return frame;
}

}  // namespace mocap::video
