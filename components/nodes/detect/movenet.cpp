// detect.movenet: people and their COCO-17 keypoints in each video frame, by MoveNet MultiPose in
// OpenCV's cv::dnn (components/detect). The model comes from the cache tools/setup.sh fills; a
// missing model stops the graph with an error naming that command.

#include <cmath>
#include <filesystem>
#include <optional>

#include "detect/model_files.hpp"
#include "detect/movenet_detector.hpp"
#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class MovenetNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Finds people and their COCO-17 keypoints in video frames (MoveNet MultiPose, cv::dnn)");
    c.input<VideoFrame>("in", "video frames, any pixel format");
    c.output<People2D>("out", "COCO-17 people in frame pixels, best first, id -1 (untracked)");
    c.param<int>("input_size", 256,
                 "network input long side, a multiple of 32: 256 fast, 384-512 for small people",
                 {128, 1024});
    c.param<double>("min_person_score", 0.25, "people scoring below are dropped", {0.0, 1.0});
    c.param<double>("min_keypoint_score", 0.3, "keypoints scoring below are missing", {0.0, 1.0});
    c.param<int>("threads", 0, "cv::dnn threads, process-wide (0: OpenCV's default)", {0, 64});
    c.param<bool>("warm_up", true, "run the network once on a blank image when the node opens");
    c.param<std::string>("model", "", "model.json (empty: the cache tools/setup.sh fills)");
  }

  void open(Context& ctx) override {
    detect::MovenetOptions options;
    options.input_size = ctx.param<int>("input_size");
    options.thresholds.min_person_score = ctx.param<float>("min_person_score");
    options.thresholds.min_keypoint_score = ctx.param<float>("min_keypoint_score");
    options.threads = ctx.param<int>("threads");
    detector_.emplace(model_path(ctx.param<std::string>("model")), options);
    // cv::dnn allocates and tunes its layers on the first forward pass (several times the later
    // ones): done here, so a live graph's first frames are not late.
    if (ctx.param<bool>("warm_up"))
      detector_->detect(ImageBuffer(options.input_size, options.input_size, PixelFormat::bgr8));
  }

  void process(Context& ctx) override {
    const auto& frame = ctx.input<VideoFrame>("in");
    People2D out;
    out.layout = LayoutId::coco17;
    out.camera = frame.camera;
    for (const detect::MovenetPerson& found : detector_->detect(frame.image)) {
      Person2D person;
      person.box = found.box;
      person.joints.assign(found.keypoints.begin(), found.keypoints.end());
      out.people.push_back(std::move(person));
    }
    ctx.send("out", std::move(out));
  }

 private:
  static std::filesystem::path model_path(const std::string& given) {
    if (given.empty()) return detect::movenet_model_json();
    if (!std::filesystem::is_regular_file(given))
      throw detect::ModelMissing("model file " + given +
                                 " not found; run tools/setup.sh --models-only to fetch the "
                                 "MoveNet model into the cache, or leave `model` empty");
    return given;
  }

  std::optional<detect::MovenetDetector> detector_;
};

MOCAP_REGISTER_NODE("detect.movenet", MovenetNode)

}  // namespace mocap::nodes
