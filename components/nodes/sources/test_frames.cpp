// test.frames: a source of synthetic video frames (each row filled with (seq + row) mod 256), for
// tests and the transport benchmark.

#include <cstring>

#include "graph/registry.hpp"
#include "graph/transport.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TestFrames : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Emits `count` synthetic video frames of width x height pixels");
    c.output<VideoFrame>("frames");
    c.param<std::int64_t>("count", 10, "frames before end of stream (0: until stopped)", {0, 1e12});
    c.param<std::int64_t>("width", 640, "pixels", {1, 16384});
    c.param<std::int64_t>("height", 480, "pixels", {1, 16384});
    c.param_choice("format", "rgb8", {"gray8", "rgb8", "bgr8", "rgba8", "bgra8"}, "pixel format");
    c.param<double>("fps", 0.0, "frames per second (0: as fast as possible)", {0, 1000});
    c.param<std::string>("camera", std::string(kDefaultCamera), "camera name (also the stream id)");
    c.param<bool>("aligned", false,
                  "fps > 0: frames taken at the multiples of the period on the wall clock and "
                  "stamped with that instant, as cameras triggered together (several such "
                  "sources share their capture times exactly)");
  }

  void open(Context& ctx) override {
    count_ = ctx.param<std::uint64_t>("count");
    width_ = ctx.param<int>("width");
    height_ = ctx.param<int>("height");
    camera_ = ctx.param<std::string>("camera");
    format_ = pixel_format_from_name(ctx.param<std::string>("format")).value();  // a choice
    const double fps = ctx.param<double>("fps");
    interval_ = std::chrono::nanoseconds(fps > 0 ? static_cast<std::int64_t>(1e9 / fps) : 0);
    aligned_ = ctx.param<bool>("aligned") && interval_.count() > 0;
  }

  void process(Context& ctx) override {
    if (count_ != 0 && seq_ >= count_) return ctx.finish();
    std::int64_t capture = 0;
    if (aligned_) {
      const std::int64_t period = interval_.count(), now = realtime_ns();
      capture = (now / period + 1) * period;  // the next multiple of the period
      if (!ctx.sleep_for(std::chrono::nanoseconds(capture - now))) return;
    } else {
      if (seq_ > 0 && interval_.count() > 0 && !ctx.sleep_for(interval_)) return;
      capture = realtime_ns();
    }
    VideoFrame frame;
    frame.header = {camera_, seq_, capture, static_cast<std::int64_t>(seq_)};
    frame.camera = camera_;
    frame.image = ImageBuffer(width_, height_, format_);
    const auto pixels = frame.image.pixels_for_writing();
    for (int row = 0; row < height_; ++row) {
      std::memset(pixels.data() + static_cast<std::size_t>(row) * frame.image.stride(),
                  static_cast<int>((seq_ + static_cast<std::uint64_t>(row)) & 0xFF),
                  static_cast<std::size_t>(frame.image.stride()));
    }
    ctx.send("frames", std::move(frame));
    ++seq_;
  }

 private:
  std::uint64_t count_ = 0, seq_ = 0;
  int width_ = 0, height_ = 0;
  std::string camera_;
  PixelFormat format_ = PixelFormat::rgb8;
  std::chrono::nanoseconds interval_{0};
  bool aligned_ = false;
};

MOCAP_REGISTER_NODE("test.frames", TestFrames)

}  // namespace mocap::nodes
