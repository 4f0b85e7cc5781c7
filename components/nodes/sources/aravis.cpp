// source.aravis: frames from a GigE Vision / USB3 Vision camera through Aravis (drivers/aravis).
// A camera that stops answering (no data for loss_timeout_ms, or Aravis' heartbeat failed) is
// reported, on stderr and as the node's status line in the graph's statistics, and reopened with
// the same settings whenever it comes back; the graph keeps running meanwhile.

#include <cmath>
#include <iostream>
#include <memory>
#include <thread>
#include <vector>

#include "camera.hpp"
#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class AravisSource : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Frames from a GigE Vision / USB3 Vision camera (Aravis); reconnects when it returns");
    c.output<VideoFrame>("frames");
    c.param<std::string>("id", "", "camera id, serial or address (empty: the first found)");
    c.param<double>("fps", 0.0, "frame rate (0: the camera's setting)", {0, 10000});
    c.param<std::int64_t>("x", 0, "region left (pixels)", {0, 65535});
    c.param<std::int64_t>("y", 0, "region top (pixels)", {0, 65535});
    c.param<std::int64_t>("width", 0, "region width (0: the camera's setting)", {0, 65535});
    c.param<std::int64_t>("height", 0, "region height (0: the camera's setting)", {0, 65535});
    c.param<double>("exposure_us", 0.0, "exposure time in us (0: the camera's)", {0, 1e8});
    c.param<double>("gain", -1.0, "gain (negative: the camera's)", {-1, 1000});
    c.param<std::string>("pixel_format", "", "Mono8, BayerRG8, RGB8, ... (empty: the camera's)");
    c.param<std::int64_t>("buffers", 0, "stream buffers (0: half a second of frames)", {0, 1024});
    c.param<std::int64_t>("count", 0, "frames before end of stream (0: until stopped)", {0, 1e12});
    c.param<std::string>("camera", std::string(kDefaultCamera),
                         "the camera's name in the messages (as in the rig file, docs/cameras.md); "
                         "also the stream id)");
    c.param<double>("loss_timeout_ms", 1000.0,
                    "no data for this long (at least 10 frame periods): the camera is lost and "
                    "reopened; 0: only Aravis' heartbeat (6 s on the fake GigE camera)",
                    {0, 3.6e6});
  }

  void open(Context& ctx) override {
    settings_ = settings_from(ctx);
    count_ = ctx.param<std::uint64_t>("count");
    camera_name_ = ctx.param<std::string>("camera");
    camera_ = std::make_unique<aravis::Camera>(settings_);  // throws naming the camera
    report_open(ctx, "streaming from");
    ctx.report_status("streaming from '" + camera_->info().id + "'");
  }

  void process(Context& ctx) override {
    if (count_ != 0 && seq_ >= count_) return ctx.finish();
    if (!camera_ && !reconnect(ctx)) return;
    // Bounded, so that a stop request is seen within a fifth of a second.
    auto frame = camera_->next(std::chrono::milliseconds(200));
    account_drops(ctx);
    if (camera_->control_lost()) return lose(ctx);
    if (frame) send(ctx, std::move(*frame));
  }

  void close(Context& ctx) override {
    if (camera_) account_drops(ctx);
    std::cerr << ctx.node_name() << ": " << seq_ << " frames, " << incomplete_ << " incomplete, "
              << skipped_ << " lost, " << reconnects_ << " reconnects\n";
  }

 private:
  static aravis::CameraSettings settings_from(Context& ctx) {
    aravis::CameraSettings s;
    s.id = ctx.param<std::string>("id");
    s.frame_rate = ctx.param<double>("fps");
    const int width = ctx.param<int>("width"), height = ctx.param<int>("height");
    if (width > 0 && height > 0)
      s.region = aravis::Region{ctx.param<int>("x"), ctx.param<int>("y"), width, height};
    s.exposure_us = ctx.param<double>("exposure_us");
    if (const double gain = ctx.param<double>("gain"); gain >= 0) s.gain = gain;
    s.pixel_format = ctx.param<std::string>("pixel_format");
    s.buffers = ctx.param<int>("buffers");
    s.loss_timeout = std::chrono::milliseconds(
        static_cast<std::int64_t>(std::llround(ctx.param<double>("loss_timeout_ms"))));
    return s;
  }

  void report_open(Context& ctx, const char* what) const {
    const aravis::Region r = camera_->region();
    std::cerr << ctx.node_name() << ": " << what << " camera '" << camera_->info().id << "' ("
              << r.width << "x" << r.height << " " << camera_->pixel_format() << ", "
              << camera_->frame_rate() << " fps, " << camera_->buffer_count() << " buffers)\n";
  }

  void send(Context& ctx, aravis::Frame frame) {
    VideoFrame message;
    // `frame` counts delivered frames: unlike the camera's 16-bit block id it never wraps and
    // stays monotonic across reconnections.
    message.header = {camera_name_, seq_, frame.capture_ns, static_cast<std::int64_t>(seq_)};
    message.camera = camera_name_;
    message.image = std::move(frame.image);
    ctx.send("frames", std::move(message));
    ++seq_;
  }

  // Incomplete and never-seen frames count as this node's drops (shown with the graph's stats).
  void account_drops(Context& ctx) {
    const aravis::StreamCounters now = camera_->counters();
    for (auto n = now.incomplete + now.skipped_ids; n > seen_drops_; ++seen_drops_)
      ctx.count_drop();
    incomplete_ = base_incomplete_ + now.incomplete;
    skipped_ = base_skipped_ + now.skipped_ids;
  }

  void lose(Context& ctx) {
    const std::string what =
        "camera '" + camera_->info().id + "' lost (" + camera_->loss_reason() + "); reconnecting";
    std::cerr << ctx.node_name() << ": " << what << "\n";
    ++losses_;
    ctx.report_status(what + " [" + std::to_string(losses_) + " lost, " +
                      std::to_string(reconnects_) + " reconnects]");
    base_incomplete_ = incomplete_;
    base_skipped_ = skipped_;
    seen_drops_ = 0;
    // Closing a camera that no longer answers waits for Aravis' timeouts (5 to 10 s on GigE):
    // that happens on its own thread, so the reconnection attempts start at once.
    closing_.emplace_back([camera = std::move(camera_)]() mutable { camera.reset(); });
  }

  // One attempt per call; between attempts the node sleeps (waking early when the graph stops).
  bool reconnect(Context& ctx) {
    try {
      camera_ = std::make_unique<aravis::Camera>(settings_);
    } catch (const std::runtime_error&) {
      ctx.sleep_for(std::chrono::milliseconds(500));
      return false;
    }
    ++reconnects_;
    report_open(ctx, "reconnected to");
    ctx.report_status("reconnected to camera '" + camera_->info().id + "' [" +
                      std::to_string(losses_) + " lost, " + std::to_string(reconnects_) +
                      " reconnects]");
    return true;
  }

  aravis::CameraSettings settings_;
  std::unique_ptr<aravis::Camera> camera_;
  std::vector<std::jthread> closing_;  // lost cameras being closed; joined when the node goes
  std::uint64_t count_ = 0, seq_ = 0;
  std::string camera_name_;
  std::uint64_t seen_drops_ = 0, incomplete_ = 0, skipped_ = 0, base_incomplete_ = 0,
                base_skipped_ = 0, reconnects_ = 0, losses_ = 0;
};

MOCAP_REGISTER_NODE("source.aravis", AravisSource)

}  // namespace mocap::nodes
