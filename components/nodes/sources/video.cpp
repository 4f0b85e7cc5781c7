// source.video: frames from a video file, a camera device (/dev/videoN), a network stream
// (rtsp://, http://) or a folder of numbered images (components/video).
//
// mode offline: every frame, as fast as the graph takes them (blocking edges lose nothing),
// stamped with its time in the source (from 0: what poses.jsonl's "time" then says).
// mode live: paced to the source. A camera or stream is read as fast as it delivers, so frames
// never wait in the driver; a file or folder is replayed at its frame rate, and a frame whose
// time has already passed when the next one is due is skipped (counted as this node's drop).
// Live frames are stamped with their capture time (CLOCK_REALTIME). Either way, put a `latest` edge
// after this node so that a slow consumer takes the newest frame.
//
// The end: a file, or a file served over HTTP/RTSP, that stops well before the frames its
// container announces (truncated, connection lost) stops the graph with an error naming the input,
// so the run ends incomplete (exit 1) instead of looking finished; a live stream announces no
// count and ends when its sender stops.
//
// loop: a file or folder starts again at its end (soak tests, installations); sequence numbers
// go on counting, offline stamps go on from the end of the previous pass. Damaged frames that
// FFmpeg could not decode are skipped: counted as drops, logged and shown in the status line.

#include <cmath>
#include <iostream>
#include <optional>

#include "graph/registry.hpp"
#include "graph/transport.hpp"
#include "video/video_source.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class VideoSourceNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Frames from a video file, camera device, RTSP/HTTP stream or image folder");
    c.output<VideoFrame>("frames", "bgr8 frames with their capture time");
    c.required_param<std::string>(
        "path", "video file, /dev/videoN (or N), rtsp:// or http:// URL, or folder of images");
    c.param_choice("mode", "auto", {"offline", "live", "auto"},
                   "offline (every frame, as fast as possible), live (paced to the source, late "
                   "frames skipped) or auto (live for devices and streams)");
    c.param<int>("decoder_threads", 0,
                 "FFmpeg decoding threads (0: one per core; needs OpenCV >= 4.7)", {0, 64});
    c.param<double>("fps", 0.0, "frame rate of an image folder (0: 30); devices: mode to ask for",
                    {0.0, 1000.0});
    c.param<int>("width", 0, "devices: frame width to ask for (0: the device's)", {0, 16384});
    c.param<int>("height", 0, "devices: frame height to ask for (0: the device's)", {0, 16384});
    c.param<std::int64_t>("count", 0, "frames to send at most (0: all)", {0, 1e12});
    c.param<int>("timeout_ms", 10000, "network streams: open and read timeout", {100, 600000});
    c.param<std::string>("camera", std::string(kDefaultCamera),
                         "the camera's name in the messages (as in the rig file, docs/cameras.md)");
    c.param<std::string>("stream", "", "stream id of the messages (default: the path)");
    c.param<bool>("loop", false, "files and folders: start again at the end (counts the passes)");
  }

  void open(Context& ctx) override {
    video::SourceOptions options;
    options.decoder_threads = ctx.param<int>("decoder_threads");
    options.folder_fps = ctx.param<double>("fps");
    options.fps = ctx.param<double>("fps");
    options.width = ctx.param<int>("width");
    options.height = ctx.param<int>("height");
    options.timeout_ms = ctx.param<int>("timeout_ms");
    const std::string path = ctx.param<std::string>("path");
    path_ = path;
    options_ = options;
    source_.emplace(path, options);
    const std::string mode = ctx.param<std::string>("mode");  // a choice: checked before open()
    live_ = mode == "auto" ? source_->live() : mode == "live";
    count_ = ctx.param<std::uint64_t>("count");
    loop_ = ctx.param<bool>("loop") && !source_->live();
    camera_ = ctx.param<std::string>("camera");
    stream_ = ctx.param<std::string>("stream");
    if (stream_.empty()) stream_ = path;
    if (options.decoder_threads > 0 && !video::decoder_threads_supported()) {
      std::cerr << ctx.node_name()
                << ": decoder_threads ignored: this OpenCV's FFmpeg backend decodes with one "
                   "thread per core (OpenCV 4.7 can set it)\n";
    }
    std::cerr << ctx.node_name() << ": " << video::name(source_->kind()) << " " << path << ", "
              << source_->width() << "x" << source_->height() << ", " << source_->fps() << " fps, "
              << (source_->frame_count() >= 0 ? std::to_string(source_->frame_count())
                                              : std::string("unknown"))
              << " frames, " << (live_ ? "live" : "offline") << "\n";
  }

  void process(Context& ctx) override {
    if (count_ != 0 && sent_ >= count_) return ctx.finish();
    std::optional<video::Frame> frame;
    if (live_ && !source_->live()) {
      frame = paced_read(ctx);
    } else {
      frame = source_->read();
    }
    if (!frame) {
      if (ctx.stop_requested()) return;  // woken from a paced wait: not the end of the file
      count_undecodable(ctx);
      if (!loop_ || source_->frames_read() == 0) return ctx.finish();
      return start_next_pass(ctx);  // the next call reads its first frame
    }
    // Offline, a file's or folder's frames are stamped with their time in the source (from 0),
    // so that outputs say where in the video they are; live, with the capture (wall) time.
    const std::int64_t stamp =
        live_ ? frame->capture_ns : std::llround((pass_offset_s_ + frame->media_time_s) * 1e9);
    last_media_time_s_ = frame->media_time_s;
    VideoFrame message;
    message.header = {stream_, sent_, stamp, frame->index};
    message.camera = camera_;
    message.image = std::move(frame->image);
    ctx.send("frames", std::move(message));
    ++sent_;
  }

  void close(Context& ctx) override {
    if (!source_) return;
    std::cerr << ctx.node_name() << ": " << sent_ << " frames sent, " << skipped_
              << " skipped (late), " << undecodable_ << " corrupt frames skipped";
    if (loop_) std::cerr << ", started again " << loops_ << " times";
    std::cerr << "\n";
  }

 private:
  // At the end of a pass: frames the file announced but FFmpeg could not decode.
  void count_undecodable(Context& ctx) {
    const std::int64_t missing = source_->frames_undecodable();
    if (missing <= 0) return;
    undecodable_ += static_cast<std::uint64_t>(missing);
    for (std::int64_t i = 0; i < missing; ++i) ctx.count_drop();
    std::cerr << ctx.node_name() << ": " << missing << " corrupt frames skipped in " << path_
              << " (" << undecodable_ << " so far)\n";
    ctx.report_status(std::to_string(undecodable_) + " corrupt frames skipped");
  }
  // Opens the file or folder again.
  void start_next_pass(Context& ctx) {
    const double period = source_->fps() > 0 ? 1.0 / source_->fps() : 1.0 / 30.0;
    pass_offset_s_ += last_media_time_s_ + period;
    source_.emplace(path_, options_);
    start_ns_ = 0;
    ++loops_;
    if (undecodable_ == 0) ctx.report_status("started again " + std::to_string(loops_) + " times");
  }

  // A file or folder replayed like a camera: frame i is due at start + its media time. Frames
  // already overdue when the one after them is due are passed over without conversion.
  std::optional<video::Frame> paced_read(Context& ctx) {
    const std::int64_t now = realtime_ns();
    if (start_ns_ == 0) start_ns_ = now;
    const double period = source_->fps() > 0 ? 1.0 / source_->fps() : 1.0 / 30.0;
    for (;;) {
      const double due_s = static_cast<double>(source_->frames_read()) * period;
      const double late_s = static_cast<double>(realtime_ns() - start_ns_) * 1e-9 - due_s;
      if (late_s < period) break;
      if (!source_->skip()) return std::nullopt;
      ++skipped_;
      ctx.count_drop();
    }
    const auto due_ns =
        start_ns_ + static_cast<std::int64_t>(
                        std::llround(1e9 * static_cast<double>(source_->frames_read()) * period));
    const std::int64_t wait = due_ns - realtime_ns();
    if (wait > 0 && !ctx.sleep_for(std::chrono::nanoseconds(wait))) return std::nullopt;
    std::optional<video::Frame> frame = source_->read();
    // Captured now, as a camera would have: latency downstream is measured from here.
    if (frame) frame->capture_ns = due_ns;
    return frame;
  }

  std::optional<video::VideoSource> source_;
  std::string path_;
  video::SourceOptions options_;
  bool live_ = false, loop_ = false;
  std::uint64_t undecodable_ = 0, loops_ = 0;
  double pass_offset_s_ = 0.0, last_media_time_s_ = 0.0;
  std::uint64_t count_ = 0, sent_ = 0, skipped_ = 0;
  std::int64_t start_ns_ = 0;
  std::string camera_;
  std::string stream_;
};

MOCAP_REGISTER_NODE("source.video", VideoSourceNode)

}  // namespace mocap::nodes
