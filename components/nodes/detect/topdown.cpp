// detect.topdown: person boxes from MB3-CenterNet every few frames, keypoints per person from
// a single-person model (MoveNet Lightning or Thunder, BlazePose) on crops that follow each person
// in between (components/detect TopDownDetector). No cap on the number of people. Models come from
// the cache tools/setup.sh fills; a missing or wrong one stops the graph naming it and that
// command.

#include <iostream>
#include <optional>

#include "detect/topdown_detector.hpp"
#include "graph/registry.hpp"
#include "network_params.hpp"
#include "people_message.hpp"
#include "topdown_params.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TopDownNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Finds every person: CenterNet boxes at a low rate, single-person keypoints (MoveNet or "
        "BlazePose) per person on crops that follow them (cv::dnn or XNNPACK)");
    c.input<VideoFrame>("in", "video frames in order, any pixel format");
    c.output<People2D>("out", "COCO-17 people in frame pixels, best first, id -1 (untracked)");
    declare_topdown_params(c);
  }

  void open(Context& ctx) override {
    const detect::TopDownOptions o = read_topdown_params(ctx);
    detector_.emplace(o, model_file(ctx, "pose_model_file", detect::model_name(o.pose_model)),
                      model_file(ctx, "box_model_file", "centernet"));
    std::cerr << "node '" << ctx.node_name() << "': top-down on "
              << detect::backend_name(detector_->backend()) << ", " << o.workers
              << " worker(s), keypoint pass every " << o.keypoint_every << " frame(s)\n";
    if (ctx.param<bool>("warm_up")) detector_->warm_up();
  }

  void process(Context& ctx) override {
    const auto& frame = ctx.input<VideoFrame>("in");
    ctx.send("out", to_people2d(detector_->detect(frame.image), frame.camera));
  }

 private:
  std::optional<detect::TopDownDetector> detector_;
};

MOCAP_REGISTER_NODE("detect.topdown", TopDownNode)

}  // namespace mocap::nodes
