// source.video: frames from a video file, a camera device (/dev/videoN), a network stream
// (rtsp://, http://) or a folder of numbered images, read by video::Playback (offline every frame
// stamped with its time in the source; live paced like a camera, late frames passed over; loop).
// Put a `latest` edge after it in live graphs. A file (also served over HTTP/RTSP) that stops well
// before the frames its container announces stops the graph with an error naming the input. A
// live stream that stops is lost, not ended: logged, shown as the status, and opened again every
// reconnect_ms while the graph (the rig's other cameras) goes on.

#include <iostream>
#include <optional>

#include "graph/registry.hpp"
#include "graph/transport.hpp"
#include "video/playback.hpp"

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
    c.param<int>("reconnect_ms", 1000,
                 "live network streams of no announced length: a stream that stops is opened "
                 "again this often until it answers (0: its stop ends this source)",
                 {0, 3600000});
    c.param<std::string>("camera", std::string(kDefaultCamera),
                         "the camera's name in the messages (as in the rig file, docs/cameras.md)");
    c.param<std::string>("stream", "", "stream id of the messages (default: the path)");
    c.param<std::int64_t>("frame_offset", 0,
                          "files: added to every frame number and time (this view's frame i is "
                          "the scene's frame i + frame_offset: views without a common clock)",
                          {-1e6, 1e6});
    c.param<bool>("loop", false, "files and folders: start again at the end (counts the passes)");
    c.param<double>("replay_fps", 0.0,
                    "files and folders read live: paced at this rate instead of their own (0)",
                    {0.0, 1000.0});
  }

  void open(Context& ctx) override {
    video::SourceOptions options;
    options.decoder_threads = ctx.param<int>("decoder_threads");
    options.folder_fps = ctx.param<double>("fps");
    options.fps = ctx.param<double>("fps");
    options.width = ctx.param<int>("width");
    options.height = ctx.param<int>("height");
    options.timeout_ms = ctx.param<int>("timeout_ms");
    const auto path = ctx.param<std::string>("path");
    const auto mode = ctx.param<std::string>("mode");  // a choice: checked before open()
    video::PlaybackOptions playback{.live = {},
                                    .loop = ctx.param<bool>("loop"),
                                    .frame_offset = ctx.param<std::int64_t>("frame_offset"),
                                    .reconnect_ms = ctx.param<int>("reconnect_ms"),
                                    .replay_fps = ctx.param<double>("replay_fps")};
    if (mode != "auto") playback.live = mode == "live";
    playback_.emplace(path, options, playback);
    count_ = ctx.param<std::uint64_t>("count");
    camera_ = ctx.param<std::string>("camera");
    stream_ = ctx.param<std::string>("stream");
    if (stream_.empty()) stream_ = path;
    std::cerr << ctx.node_name() << ": " << playback_->describe() << "\n";
  }

  void process(Context& ctx) override {
    if (count_ != 0 && sent_ >= count_) return ctx.finish();
    auto frame = playback_->next([&ctx](std::int64_t due_ns) {
      return ctx.sleep_for(std::chrono::nanoseconds(due_ns - realtime_ns()));
    });
    report(ctx);
    if (!frame) {
      if (!playback_->stopped() && !playback_->reconnecting()) ctx.finish();
      return;
    }
    VideoFrame message;
    message.header = {stream_, sent_, frame->stamp_ns, frame->frame.index};
    message.camera = camera_;
    message.image = std::move(frame->frame.image);
    ctx.send("frames", std::move(message));
    ++sent_;
  }

  void close(Context& ctx) override {
    if (!playback_) return;
    std::cerr << ctx.node_name() << ": " << sent_ << " frames sent, "
              << playback_->describe_losses() << "\n";
  }

 private:
  // Frames passed over (late, or damaged frames FFmpeg could not decode) are this node's drops;
  // what happened to the source (a stream lost or back, corrupt frames, a loop's passes) is logged
  // naming the camera and shown as the node's status.
  void report(Context& ctx) {
    for (std::uint64_t n = playback_->take_drops(); n > 0; --n) ctx.count_drop();
    if (const std::string news = playback_->take_news(); !news.empty())
      std::cerr << ctx.node_name() << " (camera " << camera_ << "): " << news << "\n";
    if (std::string status = playback_->status(); status != status_)
      ctx.report_status(status_ = std::move(status));
  }

  std::optional<video::Playback> playback_;
  std::uint64_t count_ = 0, sent_ = 0;
  std::string camera_, stream_, status_;
};

MOCAP_REGISTER_NODE("source.video", VideoSourceNode)

}  // namespace mocap::nodes
