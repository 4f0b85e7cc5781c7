// source.openpose_json: a folder of OpenPose *_keypoints.json files (BODY_25, BODY_25B, COCO-18),
// one People2D per frame number in order. A missing or malformed frame is reported and sent as a
// frame without people, so every frame of the input has its output line downstream.

#include <cmath>
#include <iostream>

#include "graph/registry.hpp"
#include "io/openpose_json.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class OpenPoseJsonSource : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Reads a folder of OpenPose *_keypoints.json files, one People2D per frame");
    c.output<People2D>("out", "2D keypoints of every person, untracked (id -1)");
    c.required_param<std::string>("path", "folder of *_keypoints.json files");
    c.param<double>("fps", 30.0, "frame rate of the video the keypoints came from", {0.1, 1000.0});
    c.param_choice("layout", "auto", {"auto", "BODY_25", "BODY_25B"},
                   "auto (detect BODY_25/BODY_25B by the keypoints), BODY_25, BODY_25B; 18 "
                   "keypoints are COCO-18 in any case");
    c.param<std::string>("stream", "", "stream id of the messages (default: the folder)");
    c.param<std::string>("camera", std::string(kDefaultCamera),
                         "the name of the camera the keypoints were detected in (as in the rig "
                         "file, docs/cameras.md)");
    c.param<std::int64_t>("frame_offset", 0,
                          "added to every frame number (and time): this view's frame i is the "
                          "scene's frame i + frame_offset (views filmed without a common clock, "
                          "`mocap rig offsets`)",
                          {-1e6, 1e6});
  }

  void open(Context& ctx) override {
    io::OpenPoseOptions options;
    const std::string layout = ctx.param<std::string>("layout");  // a choice: checked already
    options.body25 = layout == "auto"       ? io::Body25Choice::detect
                     : layout == "BODY_25B" ? io::Body25Choice::body25b
                                            : io::Body25Choice::body25;
    sequence_ = io::read_openpose_folder(ctx.param<std::string>("path"), options);
    for (const auto& p : sequence_.problems)
      std::cerr << ctx.node_name() << ": " << p.message << "\n";
    fps_ = ctx.param<double>("fps");
    stream_ = ctx.param<std::string>("stream");
    camera_ = ctx.param<std::string>("camera");
    offset_ = ctx.param<std::int64_t>("frame_offset");
    if (stream_.empty()) stream_ = ctx.param<std::string>("path");
    std::cerr << ctx.node_name() << ": " << sequence_.frames.size() << " frames, layout "
              << layout_name(sequence_.layout) << ", " << sequence_.problems.size()
              << " problem(s)\n";
  }

  void process(Context& ctx) override {
    if (next_ >= sequence_.frames.size()) {
      ctx.finish();
      return;
    }
    People2D frame = std::move(sequence_.frames[next_]);
    frame.layout = sequence_.layout;
    frame.camera = camera_;
    frame.header.stream = stream_;
    frame.header.seq = next_;
    frame.header.frame = static_cast<std::int64_t>(next_) + offset_;
    frame.header.capture_ns = static_cast<std::int64_t>(
        std::llround(1e9 * static_cast<double>(frame.header.frame) / fps_));
    ++next_;
    ctx.send("out", std::move(frame));
  }

 private:
  static std::string layout_name(LayoutId id) { return std::string(layout(id).name); }
  io::OpenPoseSequence sequence_;
  std::size_t next_ = 0;
  double fps_ = 30.0;
  std::int64_t offset_ = 0;
  std::string stream_;
  std::string camera_;
};

MOCAP_REGISTER_NODE("source.openpose_json", OpenPoseJsonSource)

}  // namespace mocap::nodes
