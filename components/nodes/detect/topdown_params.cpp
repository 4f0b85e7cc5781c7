#include "topdown_params.hpp"

#include <string>

#include "network_params.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

void declare_topdown_params(Contract& c) {
  c.param<std::string>("pose_model", "lightning",
                       "keypoints per crop: lightning (MoveNet, 192 px, fast), thunder (MoveNet, "
                       "256 px), blazepose-lite, blazepose-full or blazepose-heavy (256 px, "
                       "their pose-presence flag is the person test)");
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
  c.param<bool>("detector_whole_frame", false,
                "with detector_tiles > 1, one more detector pass on the whole frame for people "
                "wider than the tiles' overlap (close-ups), merged by NMS");
  c.param<bool>("detector_aspect", false,
                "with detector_tiles 1, the person detector sees the frame at its own aspect "
                "(512 x 896 for 16:9) instead of squeezed to 512 x 512");
  c.param<bool>("one_box_per_followed", false,
                "on a detector run a followed person is at most one box; another box "
                "overlapping them gets its own crop (two people followed as one box)");
  c.param<bool>("split_followed", false,
                "on a detector run a followed person whose box overlaps two detector boxes or "
                "more is that many people, each cropped from their box");
  c.param<double>("duplicate_similarity", 0.0,
                  "two finds sharing 3 keypoints are one person only at this keypoint "
                  "similarity (COCO OKS; 0.9: HRNet's), whatever their boxes' overlap; 0: "
                  "box overlap 0.6 or the same keypoints",
                  {0.0, 1.0});
  c.param<double>("sure_box_score", 0.0,
                  "a person box the detector scores this high is a person even when the crop's "
                  "keypoints fail the person test (only the confident keypoints kept); 0: off",
                  {0.0, 1.0});
  c.param<double>("min_pose_presence", 0.5,
                  "BlazePose: a crop whose pose-presence flag is below shows nobody "
                  "(MediaPipe's threshold)",
                  {0.0, 1.0});
  c.param<double>("box_landmark_presence", 0.5,
                  "BlazePose: a person's box spans the landmarks of at least this presence "
                  "(hidden legs included; MediaPipe's 0.5); above 1: the kept keypoints'",
                  {0.0, 2.0});
  c.param<double>("min_person_score", 0.35,
                  "a crop whose passing keypoints score less on average shows nobody", {0.0, 1.0});
  c.param<int>("min_keypoints", 6, "a crop with fewer passing keypoints shows nobody", {1, 17});
  c.param<double>("min_keypoint_score", 0.3, "keypoints scoring below are missing", {0.0, 1.0});
  c.param<double>("crop_padding", 1.25, "crop side = the person's longer box side x this",
                  {1.0, 4.0});
  declare_network_params(c, "1 per worker on XNNPACK, cv::dnn's default with 1 worker");
  c.param<int>("workers", 1,
               "copies of the keypoint network sharing each frame's crops, each on its own "
               "thread (2: both cores); the person detector then runs beside the followed "
               "people's crops",
               {1, 16});
  c.param<int>("crops_per_pass", 2,
               "crops per forward pass of the keypoint network at most (1, 2, 4 or 8); the "
               "people found do not depend on it, the time does (2: measured fastest)",
               {1, 8});
  c.param<int>("rerun_gap", 0,
               "a detector re-run after a loss only this many frames after its last run (the "
               "loss waits); 0: at every loss",
               {0, 1000});
  c.param<int>("keypoint_every", 1,
               "live: a person's keypoint pass every N frames, carried by optical flow between "
               "(a person whose flow fails gets a pass at once); 1: every frame",
               {1, 100});
  c.param<bool>("detector_in_background", false,
                "live: the person detector runs on a thread of its own and no frame waits for "
                "it; newcomers are found a few frames later (what is found depends on timing: "
                "not for files)");
  c.param<bool>("warm_up", true,
                "build the networks for every batch shape when the node opens, so that a live "
                "source's first frames are not late (mocap reconstruct turns it off for files: "
                "the shapes are then built as they are met)");
  c.param<std::string>("pose_model_file", "", "model.json (empty: the cache)");
  c.param<std::string>("box_model_file", "", "CenterNet model.json (empty: the cache)");
}

detect::TopDownOptions read_topdown_params(Context& ctx) {
  detect::TopDownOptions o;
  const std::string model = ctx.param<std::string>("pose_model");
  o.pose_model = detect::parse_pose_model(model);
  o.min_pose_presence = ctx.param<float>("min_pose_presence");
  o.box_landmark_presence = ctx.param<float>("box_landmark_presence");
  o.detect_every = ctx.param<int>("detect_every");
  o.min_box_score = ctx.param<float>("min_box_score");
  o.detector_tiles = ctx.param<int>("detector_tiles");
  o.detector_whole_frame = ctx.param<bool>("detector_whole_frame");
  o.detector_aspect = ctx.param<bool>("detector_aspect");
  o.one_box_per_followed = ctx.param<bool>("one_box_per_followed");
  o.split_followed = ctx.param<bool>("split_followed");
  o.duplicate_similarity = ctx.param<float>("duplicate_similarity");
  o.sure_box_score = ctx.param<float>("sure_box_score");
  o.min_person_score = ctx.param<float>("min_person_score");
  o.min_keypoints = ctx.param<int>("min_keypoints");
  o.min_keypoint_score = ctx.param<float>("min_keypoint_score");
  o.crop_padding = ctx.param<float>("crop_padding");
  const NetworkParams network = read_network_params(ctx);
  o.backend = network.backend;
  o.threads = network.threads;
  o.workers = ctx.param<int>("workers");
  o.keypoint_every = ctx.param<int>("keypoint_every");
  o.rerun_gap = ctx.param<int>("rerun_gap");
  o.crops_per_pass = ctx.param<int>("crops_per_pass");
  o.detector_in_background = ctx.param<bool>("detector_in_background");
  return o;
}

}  // namespace mocap::nodes
