// sink.overlay: the 2D input beside the 3D result, as an MP4 video and/or PNG snapshots. The
// framework joins the inputs by frame number (Contract::join, graph/synchronizer.hpp): process()
// sees one frame's 2D people, 3D people and video frame, each present or missing; a frame with
// both people is drawn (viz/overlay_renderer), on its video frame when there is one. With
// `video_path` the frame under the people is read again from the file by its number
// (video::FrameReader) instead of coming on the `video` port, so no decoded frame waits here for
// its 3D (the offline fit sends it a window later).

#include <iostream>
#include <memory>
#include <optional>

#include "graph/registry.hpp"
#include "video/frame_reader.hpp"
#include "video/mp4_writer.hpp"
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
    c.param<std::string>("h264_preset", std::string(video::kDefaultH264Preset),
                         "libx264 preset of the MP4 (ultrafast: less CPU, larger file)");
    c.param<std::int64_t>("png_every", 0, "a PNG of every Nth drawn frame; 0: none", {0, 1e9});
    c.param<std::string>("png_dir", "", "folder for the PNGs (overlay_<frame>.png)");
    c.param<std::int64_t>("canvas_width", 1920, "2D input's pixel space (its video's size)",
                          {16, 16384});
    c.param<std::int64_t>("canvas_height", 1080, "2D input's pixel space (its video's size)",
                          {16, 16384});
    c.param<std::int64_t>("panel_height", 480, "output height in pixels", {16, 16384});
    c.param<double>("view_yaw_deg", 35.0, "3D view: turn about the vertical", {-180.0, 180.0});
    c.param<double>("view_pitch_deg", 30.0, "3D view: looking down by", {-89.0, 89.0});
    // The 3D of a frame comes after its 2D by the lag of the stages between (the offline fit
    // works in windows of 64 frames per person): held up to sync_bound frames per input. A message
    // that comes after its frame went on partial cannot be drawn (its partner went with the
    // frame): counted and dropped (sync_late) rather than passed on as a frame of its own.
    c.join({{"people2d", "people3d", "video"}, SyncKey::frame, 256, 0.0, 0.0, LateMessages::drop});
  }

  void open(Context& ctx) override {
    viz::OverlayOutputOptions out;
    out.video = ctx.param<std::string>("video");
    out.fps = ctx.param<double>("fps");
    out.h264_preset = ctx.param<std::string>("h264_preset");
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
    if (const auto path = ctx.param<std::string>("video_path"); !path.empty())
      frames_.emplace(path);
  }

  void process(Context& ctx) override {
    if (!ctx.has("people2d") || !ctx.has("people3d")) {
      // A frame the detector skipped (video only) is no loss; 2D without 3D or the reverse is
      // (the synchroniser's line in the statistics says which input was missing or late).
      if (ctx.has("people2d") || ctx.has("people3d")) {
        ++undrawn_;
        ctx.count_drop();
      }
      return;
    }
    const auto& people3d = ctx.input<People3D>("people3d");
    ImageBuffer background =
        ctx.has("video") ? ctx.input<VideoFrame>("video").image : ImageBuffer();
    if (frames_) {
      if (auto frame = frames_->frame(people3d.header.frame)) background = std::move(frame->image);
    }
    output_->write(renderer_->render(ctx.input<People2D>("people2d"), people3d, background,
                                     {people3d.header.frame, output_->pictures_per_second()}),
                   people3d.header.frame);
  }

  void close(Context& ctx) override {
    if (!output_) return;
    output_->close();
    std::cerr << "sink.overlay '" << ctx.node_name() << "': " << output_->pictures()
              << " frames drawn, " << undrawn_ << " with only 2D or only 3D people, "
              << output_->pngs() << " PNGs";
    if (frames_)
      std::cerr << "; " << frames_->returned() << " video frames read again, "
                << frames_->passed_over() << " passed over, " << frames_->reopened() << " restarts";
    std::cerr << "\n";
  }

 private:
  std::unique_ptr<viz::OverlayOutput> output_;
  std::unique_ptr<viz::OverlayRenderer> renderer_;
  std::optional<video::FrameReader> frames_;  // with video_path
  std::int64_t undrawn_ = 0;
};

MOCAP_REGISTER_NODE("sink.overlay", OverlaySink)

}  // namespace mocap::nodes
