// detect.topdown: person boxes from MB3-CenterNet every few frames, keypoints per person from
// MoveNet single-pose on crops that follow each person in between (components/detect
// TopDownDetector). No cap on the number of people. Models come from the cache tools/setup.sh
// fills; a missing or wrong one stops the graph naming it and that command.

#include <iostream>
#include <optional>

#include "detect/model_files.hpp"
#include "detect/topdown_detector.hpp"
#include "graph/registry.hpp"
#include "people_message.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TopDownNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Finds every person: CenterNet boxes at a low rate, MoveNet single-pose keypoints per "
        "person on crops that follow them (cv::dnn or XNNPACK)");
    c.input<VideoFrame>("in", "video frames in order, any pixel format");
    c.output<People2D>("out", "COCO-17 people in frame pixels, best first, id -1 (untracked)");
    c.param<std::string>("pose_model", "lightning",
                         "keypoints per crop: lightning (192 px, fast) or thunder (256 px)");
    c.param<int>("detect_every", 10,
                 "frames between person-detector runs (1: every frame); it also runs after a "
                 "frame that lost somebody",
                 {1, 1000});
    c.param<double>("min_box_score", 0.3, "CenterNet person boxes scoring below are ignored",
                    {0.0, 1.0});
    c.param<int>("detector_tiles", 1,
                 "person detector on the whole frame stretched (1) or on N square tiles of a "
                 "wide frame, people keeping their shape",
                 {1, 8});
    c.param<double>("min_person_score", 0.35,
                    "a crop whose passing keypoints score less on average shows nobody",
                    {0.0, 1.0});
    c.param<int>("min_keypoints", 6, "a crop with fewer passing keypoints shows nobody", {1, 17});
    c.param<double>("min_keypoint_score", 0.3, "keypoints scoring below are missing", {0.0, 1.0});
    c.param<double>("crop_padding", 1.25, "crop side = the person's longer box side x this",
                    {1.0, 4.0});
    c.param<std::string>("backend", "auto",
                         "network runtime: auto (XNNPACK when built in, else cv::dnn), xnnpack, "
                         "opencv");
    c.param<int>("threads", 0,
                 "network threads (0: XNNPACK 1, cv::dnn OpenCV's default); cv::dnn's setting is "
                 "process-wide",
                 {0, 64});
    c.param<std::string>("pose_model_file", "", "model.json (empty: the cache)");
    c.param<std::string>("box_model_file", "", "CenterNet model.json (empty: the cache)");
  }

  void open(Context& ctx) override {
    detect::TopDownOptions o;
    const std::string model = ctx.param<std::string>("pose_model");
    if (model != "lightning" && model != "thunder")
      throw std::invalid_argument("pose_model must be lightning or thunder, got '" + model + "'");
    o.pose_model =
        model == "thunder" ? detect::SinglePoseModel::thunder : detect::SinglePoseModel::lightning;
    o.detect_every = ctx.param<int>("detect_every");
    o.min_box_score = ctx.param<float>("min_box_score");
    o.detector_tiles = ctx.param<int>("detector_tiles");
    o.min_person_score = ctx.param<float>("min_person_score");
    o.min_keypoints = ctx.param<int>("min_keypoints");
    o.min_keypoint_score = ctx.param<float>("min_keypoint_score");
    o.crop_padding = ctx.param<float>("crop_padding");
    o.backend = detect::parse_backend(ctx.param<std::string>("backend"));
    o.threads = ctx.param<int>("threads");
    detector_.emplace(
        o,
        file_or_cache(ctx.param<std::string>("pose_model_file"), detect::model_name(o.pose_model)),
        file_or_cache(ctx.param<std::string>("box_model_file"), "centernet"));
    std::cerr << "node '" << ctx.node_name() << "': top-down on "
              << detect::backend_name(detector_->backend()) << "\n";
  }

  void process(Context& ctx) override {
    ctx.send("out", to_people2d(detector_->detect(ctx.input<VideoFrame>("in").image)));
  }

 private:
  static std::filesystem::path file_or_cache(const std::string& given, std::string_view name) {
    if (given.empty()) return detect::cached_model_json(name);
    if (!std::filesystem::is_regular_file(given))
      throw detect::ModelMissing("model file " + given + " not found; " + detect::kFetchModelsHint +
                                 ", or leave the parameter empty");
    return given;
  }

  std::optional<detect::TopDownDetector> detector_;
};

MOCAP_REGISTER_NODE("detect.topdown", TopDownNode)

}  // namespace mocap::nodes
