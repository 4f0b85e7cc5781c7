// detect.tiles: MoveNet MultiPose on overlapping tiles of each frame plus one pass over the whole
// frame, for small and distant people and for more than 6 people (components/detect
// TiledDetector). The model comes from the cache tools/setup.sh fills.

#include <iostream>
#include <optional>

#include "detect/tiled_detector.hpp"
#include "graph/registry.hpp"
#include "network_params.hpp"
#include "people_message.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TilesNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Finds small and distant people: MoveNet MultiPose on overlapping tiles and on the "
        "whole frame, duplicates merged (cv::dnn or XNNPACK)");
    c.input<VideoFrame>("in", "video frames, any pixel format");
    c.output<People2D>("out", "COCO-17 people in frame pixels, best first, id -1 (untracked)");
    c.param<int>("columns", 2, "tiles across", {1, 8});
    c.param<int>("rows", 2, "tiles down", {1, 8});
    c.param<double>("overlap", 0.25, "share of a tile's side shared with its neighbour",
                    {0.0, 0.8});
    c.param<int>("tile_input_size", 256, "network input long side per tile, a multiple of 32",
                 {64, 1024});
    c.param<int>("frame_input_size", 256,
                 "network input long side of the whole-frame pass (0: none), a multiple of 32",
                 {0, 1024});
    c.param<double>("min_person_score", 0.25, "people scoring below are dropped", {0.0, 1.0});
    c.param<double>("min_keypoint_score", 0.3, "keypoints scoring below are missing", {0.0, 1.0});
    declare_network_params(c, "XNNPACK 1, cv::dnn OpenCV's default");
    c.param<std::string>("model", "", "model.json (empty: the cache tools/setup.sh fills)");
  }

  void open(Context& ctx) override {
    detect::TileOptions o;
    o.columns = ctx.param<int>("columns");
    o.rows = ctx.param<int>("rows");
    o.overlap = ctx.param<float>("overlap");
    o.tile_input_size = ctx.param<int>("tile_input_size");
    o.frame_input_size = ctx.param<int>("frame_input_size");
    o.thresholds.min_person_score = ctx.param<float>("min_person_score");
    o.thresholds.min_keypoint_score = ctx.param<float>("min_keypoint_score");
    const NetworkParams network = read_network_params(ctx);
    o.backend = network.backend;
    o.threads = network.threads;
    detector_.emplace(model_file(ctx, "model", "movenet-multipose"), o);
    std::cerr << "node '" << ctx.node_name() << "': tiles on "
              << detect::backend_name(detector_->backend()) << "\n";
  }

  void process(Context& ctx) override {
    ctx.send("out", to_people2d(detector_->detect(ctx.input<VideoFrame>("in").image)));
  }

 private:
  std::optional<detect::TiledDetector> detector_;
};

MOCAP_REGISTER_NODE("detect.tiles", TilesNode)

}  // namespace mocap::nodes
