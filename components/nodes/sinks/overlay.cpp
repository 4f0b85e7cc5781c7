// sink.overlay: the 2D input beside the 3D result, as an MP4 video and/or PNG snapshots. The
// inputs arrive unsynchronised on their ports; frames are joined by number (viz/overlay_inputs)
// and drawn by viz/overlay_renderer. The frame under the 2D people comes from the `video` port
// (cameras, streams) or, with `video_path`, is read again from the file by its frame number
// (video::FrameReader), so that no decoded frame waits here for its 3D.

#include <chrono>
#include <iostream>
#include <memory>
#include <optional>

#include "graph/registry.hpp"
#include "video/frame_reader.hpp"
#include "viz/overlay_inputs.hpp"
#include "viz/overlay_output.hpp"
#include "viz/overlay_renderer.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class OverlaySink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Draws the 2D input beside the 3D skeletons (second viewpoint) into an MP4 and/or PNGs");
    c.input<People2D>("people2d", "the tracked 2D people (any keypoint layout)");
    c.input<People3D>("people3d", "the reconstructed 3D people");
    c.input<VideoFrame>("video",
                        "the frames the 2D people were found in (drawn under them); unused "
                        "with video_path",
                        PortFlag::optional);
    c.param<std::string>("video_path", "",
                         "video file or image folder the 2D people were found in, read again by "
                         "frame number (instead of the video port; not for cameras and streams)");
    c.param<std::string>("video", "",
                         "MP4 file to write (fragmented, H.264: plays even if the run is killed); "
                         "empty: none");
    c.param<double>("fps", 30.0, "frame rate of the MP4", {0.1, 1000.0});
    c.param<std::int64_t>("png_every", 0, "a PNG of every Nth drawn frame; 0: none", {0, 1e9});
    c.param<std::string>("png_dir", "", "folder for the PNGs (overlay_<frame>.png)");
    c.param<std::int64_t>("canvas_width", 1920, "2D input's pixel space (its video's size)",
                          {16, 16384});
    c.param<std::int64_t>("canvas_height", 1080, "2D input's pixel space (its video's size)",
                          {16, 16384});
    c.param<std::int64_t>("panel_height", 480, "output height in pixels", {16, 16384});
    c.param<double>("view_yaw_deg", 35.0, "3D view: turn about the vertical", {-180.0, 180.0});
    c.param<double>("view_pitch_deg", 30.0, "3D view: looking down by", {-89.0, 89.0});
    c.param<std::int64_t>("max_pending", 64, "incomplete frames kept at most", {1, 100000});
    c.param<bool>("wait_for_video", false, "draw a frame only once its video frame is there");
  }

  void open(Context& ctx) override {
    viz::OverlayOutputOptions out;
    out.video = ctx.param<std::string>("video");
    out.fps = ctx.param<double>("fps");
    out.png_every = ctx.param<int>("png_every");
    out.png_dir = ctx.param<std::string>("png_dir");
    if (out.video.empty() && out.png_every == 0)
      throw std::invalid_argument("nothing to write: set 'video' and/or 'png_every'");
    output_ = std::make_unique<viz::OverlayOutput>(out);
    viz::OverlayOptions look;
    look.canvas_width = ctx.param<int>("canvas_width");
    look.canvas_height = ctx.param<int>("canvas_height");
    look.panel_height = ctx.param<int>("panel_height");
    look.view_yaw_deg = ctx.param<float>("view_yaw_deg");
    look.view_pitch_deg = ctx.param<float>("view_pitch_deg");
    renderer_ = std::make_unique<viz::OverlayRenderer>(look);
    inputs_ = std::make_unique<viz::OverlayInputs>(ctx.param<std::size_t>("max_pending"),
                                                   ctx.param<bool>("wait_for_video"));
    if (const auto path = ctx.param<std::string>("video_path"); !path.empty())
      frames_.emplace(path);
  }

  void process(Context& ctx) override {
    const std::int64_t dropped_before = inputs_->dropped();
    if (ctx.has("people2d")) inputs_->add(ctx.input_ptr<People2D>("people2d"));
    if (ctx.has("people3d")) inputs_->add(ctx.input_ptr<People3D>("people3d"));
    if (ctx.has("video") && !frames_) inputs_->add(ctx.input_ptr<VideoFrame>("video"));
    draw(inputs_->take_ready());
    for (auto d = dropped_before; d < inputs_->dropped(); ++d) ctx.count_drop();
  }

  void close(Context& ctx) override {
    if (!inputs_) return;
    draw(inputs_->take_remaining());
    output_->close();
    std::cerr << "sink.overlay '" << ctx.node_name() << "': " << output_->pictures()
              << " frames drawn, " << inputs_->dropped() << " dropped, " << output_->pngs()
              << " PNGs";
    if (frames_)
      std::cerr << "; " << frames_->returned() << " video frames read again, "
                << frames_->passed_over() << " passed over, " << frames_->reopened() << " restarts";
    std::cerr << "\n";
  }

 private:
  void draw(const std::vector<viz::OverlayFrame>& frames) {
    for (const viz::OverlayFrame& f : frames) {
      ImageBuffer background = f.video ? f.video->image : ImageBuffer();
      if (frames_) {
        if (auto frame = frames_->frame(f.frame)) background = std::move(frame->image);
      }
      output_->write(renderer_->render(*f.people2d, *f.people3d, background, {f.frame, rate()}),
                     f.frame);
    }
  }

  // Frames drawn per second of wall-clock time, smoothed: how fast the whole graph runs.
  double rate() {
    const auto now = std::chrono::steady_clock::now();
    if (last_ != std::chrono::steady_clock::time_point{}) {
      const double seconds = std::chrono::duration<double>(now - last_).count();
      if (seconds > 0.0) fps_ = fps_ > 0.0 ? 0.9 * fps_ + 0.1 / seconds : 1.0 / seconds;
    }
    last_ = now;
    return fps_;
  }

  std::unique_ptr<viz::OverlayOutput> output_;
  std::unique_ptr<viz::OverlayRenderer> renderer_;
  std::unique_ptr<viz::OverlayInputs> inputs_;
  std::optional<video::FrameReader> frames_;  // with video_path
  std::chrono::steady_clock::time_point last_{};
  double fps_ = 0.0;
};

MOCAP_REGISTER_NODE("sink.overlay", OverlaySink)

}  // namespace mocap::nodes
