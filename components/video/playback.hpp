#pragma once
// A video source read the way a graph's source reads it: a file or folder either as fast as it is
// taken (offline) or replayed like a camera (paced), optionally started again at its end (loop),
// every frame stamped.
//
// Paced: frame i of a file or folder is due at the start + its time in the source; a frame whose
// time has already passed when the next one is due is passed over without conversion (counted as
// late), and a frame's stamp is the time it was due (CLOCK_REALTIME), as a camera would have
// captured it. Cameras and network streams are never paced (they run on their own) and are stamped
// with their capture time. Offline, a frame is stamped with its time in the source (from 0) plus
// the length of the passes before it, so that outputs say where in the video they are. A frame
// offset shifts indices and stamps alike (PlaybackOptions::frame_offset).
//
// A network stream read live that stops (the server went away, the network is down, or the server
// ended a stream that announced no length: a camera has no end) is lost, not ended: it is opened
// again every reconnect interval until it answers, and its frames go on with the next indices
// (PlaybackOptions::reconnect_ms). A stream that announced its length (a file served over HTTP or
// RTSP) ends at its end.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "video/video_source.hpp"

namespace mocap::video {

struct PlaybackOptions {
  // Live: files and folders paced, frames stamped with the wall clock. Offline: every frame as
  // fast as taken, stamped with its time in the source. Unset: live for cameras and streams.
  std::optional<bool> live;
  bool loop = false;  // start a file or folder again at its end (soak tests, installations)
  // Added to every frame's index, and its period times this to every stamp: this source's frame i
  // is the scene's frame i + frame_offset (views filmed without a common clock).
  std::int64_t frame_offset = 0;
  // Network streams read live: a stream that stops is opened again this often until it answers;
  // 0: its stop is its end.
  int reconnect_ms = 1000;
  // Files and folders read live: paced at this rate instead of their own (a 10 fps clip replayed
  // as a 25 fps camera, to measure a live pipeline at a camera's rate); 0: their own rate.
  double replay_fps = 0.0;
};

struct StampedFrame {
  Frame frame;
  std::int64_t stamp_ns = 0;
};

class Playback {
 public:
  // Waits until the CLOCK_REALTIME time given; false when the wait was cut short (a stop).
  using WaitUntil = std::function<bool(std::int64_t due_ns)>;

  // Opens the source (throws InputError naming it, as VideoSource does).
  Playback(std::string path, SourceOptions source_options, PlaybackOptions options);

  // The next frame; nullopt at the end of the last pass, when `wait` was cut short (stopped()),
  // or while a lost stream is not back (reconnecting(): call again, it waits for the next
  // attempt). Errors of the source (a truncated file, a camera unplugged) are thrown as
  // VideoSource throws them.
  std::optional<StampedFrame> next(const WaitUntil& wait);
  // What happened to the source since the last call, for logs (a stream lost or back, corrupt
  // frames skipped): empty when nothing.
  std::string take_news();
  // Frames passed over (late, or undecodable) since the last call: a node's drops.
  std::uint64_t take_drops();
  // The source's state in a few words, for a status line: "lost, reconnecting", "N corrupt frames
  // skipped", "reconnected", "started again P times", or empty while nothing of note happened.
  std::string status() const;

  const VideoSource& source() const { return source_; }
  // For logs: "file PATH, WxH, F fps, N frames, offline", with a note when an option asked for
  // cannot take effect here (decoder threads on OpenCV < 4.7).
  std::string describe() const;
  // For logs at the end: "L skipped (late), U corrupt frames skipped[, started again P times]".
  std::string describe_losses() const;
  bool live() const { return live_; }
  bool loops() const { return loop_; }
  std::uint64_t late_frames_passed_over() const { return late_; }
  // Frames the container announced that FFmpeg could not decode, over the passes finished.
  std::uint64_t undecodable_frames() const { return undecodable_; }
  std::uint64_t passes_started_again() const { return passes_; }
  bool stopped() const { return stopped_; }                  // a paced wait was cut short
  bool reconnecting() const { return lost_since_ns_ != 0; }  // a lost stream, not back yet
  std::uint64_t reconnects() const { return reconnects_; }   // times a lost stream came back
  std::uint64_t losses() const { return losses_; }           // times a stream was lost

 private:
  std::optional<Frame> paced_read(const WaitUntil& wait);
  bool start_next_pass();  // false when the source is not looped or had no frame
  bool may_reconnect() const;
  void lose_stream();
  bool reconnect(const WaitUntil& wait);  // false while the stream is not back (or stopped)
  double frame_period_s() const;
  double pace_period_s() const;  // between paced frames: replay_fps's, else frame_period_s()
  void add_news(const std::string& text);

  std::string path_;
  SourceOptions source_options_;
  VideoSource source_;
  bool live_ = false, paced_ = false, loop_ = false, stopped_ = false;
  std::int64_t frame_offset_ = 0;
  std::int64_t pace_start_ns_ = 0;  // when the pass's first frame was due (0: not yet)
  double pass_offset_s_ = 0.0, last_media_time_s_ = 0.0;
  std::uint64_t late_ = 0, undecodable_ = 0, passes_ = 0;
  int reconnect_ms_ = 0;
  double replay_fps_ = 0.0;
  std::int64_t lost_since_ns_ = 0, next_attempt_ns_ = 0;  // while a stream is lost
  std::int64_t index_base_ = 0;  // frames of the connections before this one
  std::uint64_t reconnects_ = 0, losses_ = 0, attempts_ = 0;
  std::uint64_t drops_taken_ = 0;  // late_ + undecodable_ as of the last take_drops()
  std::string news_;
};

}  // namespace mocap::video
