// detect.movenet: people and their COCO-17 keypoints in each video frame, by MoveNet MultiPose
// (components/detect) on XNNPACK or cv::dnn, on one or several copies of the network working on
// consecutive frames (outputs in frame order). The model comes from the cache tools/setup.sh
// fills; a missing model stops the graph with an error naming that command.

#include <deque>
#include <filesystem>
#include <iostream>
#include <optional>

#include "detect/movenet_workers.hpp"
#include "graph/registry.hpp"
#include "network_params.hpp"
#include "people_message.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class MovenetNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Finds people and their COCO-17 keypoints in video frames (MoveNet MultiPose)");
    c.input<VideoFrame>("in", "video frames, any pixel format");
    c.output<People2D>("out", "COCO-17 people in frame pixels, best first, id -1 (untracked)");
    c.param<int>("input_size", 256,
                 "network input long side, a multiple of 32: 256 fast, 384-512 for small people",
                 {128, 1024});
    c.param<double>("min_person_score", 0.25, "people scoring below are dropped", {0.0, 1.0});
    c.param<double>("min_keypoint_score", 0.3, "keypoints scoring below are missing", {0.0, 1.0});
    declare_network_params(c, "XNNPACK 1, cv::dnn OpenCV's default with 1 worker, else 1");
    c.param<int>("workers", 1,
                 "copies of the network on consecutive frames, each on its own thread (2: both "
                 "cores); outputs stay in frame order",
                 {1, 16});
    c.param<bool>("warm_up", true, "run the network on blank 4:3 and 16:9 frames when it opens");
    c.param<std::string>("model", "", "model.json (empty: the cache tools/setup.sh fills)");
  }

  void open(Context& ctx) override {
    detect::MovenetOptions options;
    options.input_size = ctx.param<int>("input_size");
    options.thresholds.min_person_score = ctx.param<float>("min_person_score");
    options.thresholds.min_keypoint_score = ctx.param<float>("min_keypoint_score");
    const NetworkParams network = read_network_params(ctx);
    options.backend = network.backend;
    options.threads = network.threads;
    workers_.emplace(model_file(ctx, "model", "movenet-multipose"), options,
                     ctx.param<int>("workers"));
    std::cerr << "node '" << ctx.node_name() << "': MoveNet on "
              << detect::backend_name(workers_->backend()) << ", " << workers_->workers()
              << " worker(s)\n";
    // The runtimes allocate (XNNPACK: build) per input size on the first forward pass: done here
    // for the usual frame shapes, so a live graph's first frames are not late.
    if (ctx.param<bool>("warm_up")) {
      const int s = options.input_size;
      workers_->warm_up({ImageBuffer(s, s * 3 / 4, PixelFormat::bgr8),
                         ImageBuffer(s, s * 9 / 16, PixelFormat::bgr8)});
    }
  }

  void process(Context& ctx) override {
    headers_.push_back(ctx.header());
    for (auto& people : workers_->push(ctx.input<VideoFrame>("in").image)) send(ctx, people);
  }

  void close(Context& ctx) override {
    if (!workers_) return;
    for (auto& people : workers_->finish()) send(ctx, people);
  }

 private:
  // The oldest frame's people, with that frame's header.
  void send(Context& ctx, const std::vector<detect::MovenetPerson>& found) {
    People2D out = to_people2d(found);
    out.header = headers_.front();
    headers_.pop_front();
    ctx.send("out", std::move(out));
  }

  std::optional<detect::MovenetWorkers> workers_;
  std::deque<Header> headers_;  // of the frames in work, oldest first
};

MOCAP_REGISTER_NODE("detect.movenet", MovenetNode)

}  // namespace mocap::nodes
