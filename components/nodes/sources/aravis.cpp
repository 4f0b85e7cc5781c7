// source.aravis: frames from a GigE Vision / USB3 Vision camera through Aravis (drivers/aravis).
// A camera that stops answering (no data for loss_timeout_ms, or Aravis' heartbeat failed) is
// reported, on stderr and as the node's status line in the graph's statistics, and reopened with
// the same settings whenever it comes back (aravis::ReconnectingCamera); the graph keeps running.

#include <cmath>
#include <iostream>
#include <memory>

#include "graph/registry.hpp"
#include "reconnecting_camera.hpp"

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
    count_ = ctx.param<std::uint64_t>("count");
    camera_name_ = ctx.param<std::string>("camera");
    camera_ = std::make_unique<aravis::ReconnectingCamera>(settings_from(ctx));  // throws naming it
    std::cerr << ctx.node_name() << ": streaming from " << camera_->description() << "\n";
    ctx.report_status(camera_->status());
  }

  void process(Context& ctx) override {
    if (count_ != 0 && seq_ >= count_) return ctx.finish();
    // Bounded, so that a stop request is seen within a fifth of a second.
    aravis::Poll poll = camera_->poll(std::chrono::milliseconds(200));
    // Incomplete and never-seen frames count as this node's drops (shown with the graph's stats).
    for (std::uint64_t i = 0; i < poll.new_drops; ++i) ctx.count_drop();
    if (!poll.news.empty()) {
      std::cerr << ctx.node_name() << ": " << poll.news << "\n";
      ctx.report_status(camera_->status());
    }
    if (poll.away) ctx.sleep_for(std::chrono::milliseconds(500));  // wakes early on a stop
    if (poll.frame) send(ctx, std::move(*poll.frame));
  }

  void close(Context& ctx) override {
    const aravis::CaptureTotals& t = camera_->totals();
    std::cerr << ctx.node_name() << ": " << seq_ << " frames, " << t.incomplete << " incomplete, "
              << t.skipped << " lost, " << t.reconnects << " reconnects\n";
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

  std::unique_ptr<aravis::ReconnectingCamera> camera_;
  std::uint64_t count_ = 0, seq_ = 0;
  std::string camera_name_;
};

MOCAP_REGISTER_NODE("source.aravis", AravisSource)

}  // namespace mocap::nodes
