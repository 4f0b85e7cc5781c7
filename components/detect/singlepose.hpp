#pragma once
// Single-person keypoint models for the crops of top-down detection:
//  - MoveNet single-pose (Lightning 192 × 192, Thunder 256 × 256): the keypoints of the one person
//    nearest the centre of a square crop (below);
//  - BlazePose's landmark models (lite, full, heavy; 256 × 256, MediaPipe's GHUM 3D pose
//    landmarks): 39 landmarks × (x, y, z, visibility, presence) and a pose-presence flag, the
//    network's own answer to "is there a person in this crop". decode_blazepose keeps the 17 that
//    COCO-17 names (nose, eyes, ears, shoulders, elbows, wrists, hips, knees, ankles: the same
//    body points by name, not by annotation: docs/models.md), scored by σ(visibility) as
//    MediaPipe does.
//
// MoveNet: The CNN (MobileNetV2 + FPN + four CenterNet heads) runs on
// either network runtime through GraphRunner; the graph's own post-processing (argmax, gathers) is
// decode_singlepose here, the arithmetic read from the graph and its constants
// (docs/detection-strategies.md):
//
//  1. centre = σ(centre logit) · w(y, x), w = 1 / (distance to the grid centre (h/2, w/2) + 1.8);
//     the centre cell (cy, cx) is its first maximum in row-major order;
//  2. per keypoint k, the regressed position r_k = (cy, cx) + regress_k(cy, cx);
//  3. S_k(Y, X) = σ(heatmap_k(Y, X)) / (|(Y, X) − r_k| + 1.8); (Y*, X*) its first maximum;
//  4. y = (Y* + offset_k,y(Y*, X*)) · f, x = (X* + offset_k,x(Y*, X*)) · f with f = 1/h as the
//     model stores it (float16), score = σ(heatmap_k(Y*, X*)).
// Many crops go through one forward pass (batch N): the graph is fed after its batch-of-one input
// reshuffles.

#include <array>
#include <filesystem>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "detect/graph_runner.hpp"
#include "detect/movenet_decoder.hpp"

namespace mocap::detect {

enum class SinglePoseModel { lightning, thunder, blazepose_lite, blazepose_full, blazepose_heavy };

// "movenet-lightning", "movenet-thunder", "blazepose-lite|full|heavy": the model's folder in the
// cache.
std::string_view model_name(SinglePoseModel model);
// The model's short name as parameters spell it: "lightning", "thunder", "blazepose-lite"...
std::string_view short_name(SinglePoseModel model);
// The model of a short name; throws std::invalid_argument naming the accepted names.
SinglePoseModel parse_pose_model(std::string_view name);
// "lightning|thunder|blazepose-lite|blazepose-full|blazepose-heavy", for help texts.
std::string_view pose_model_names();
bool is_blazepose(SinglePoseModel model);
// 192 / 256: the square crop the model takes.
int input_size(SinglePoseModel model);

// The model's own output for one crop: 17 × (y, x, score), y and x normalised to the crop.
using SinglePoseKeypoints = std::array<std::array<float, 3>, kMovenetKeypoints>;

// One crop's answer: its keypoints and, from models that have one (BlazePose), the network's
// pose-presence flag in [0, 1]; kNoPresence for MoveNet, whose person test is its keypoints'.
inline constexpr float kNoPresence = -1.0f;
// BlazePose's 33 body landmarks (MediaPipe's order: head, arms, hands, legs, heels, toes), each
// (y, x normalised to the crop, σ(presence): the landmark lies in the picture, seen or occluded).
inline constexpr int kBlazePoseBody = 33;
using BodyLandmarks = std::array<std::array<float, 3>, kBlazePoseBody>;
struct SinglePose {
  SinglePoseKeypoints keypoints{};
  float presence = kNoPresence;
  BodyLandmarks body{};    // BlazePose only
  int body_landmarks = 0;  // kBlazePoseBody from BlazePose, 0 from MoveNet
};

// BlazePose: the 39 landmarks the model outputs (33 of the body, 6 auxiliary), 5 values each.
inline constexpr int kBlazePoseLandmarks = 39;
// The BlazePose landmark in each COCO-17 slot (MediaPipe's pose landmark indices).
inline constexpr std::array<int, kMovenetKeypoints> kBlazePoseToCoco = {
    0, 2, 5, 7, 8, 11, 12, 13, 14, 15, 16, 23, 24, 25, 26, 27, 28};

// Decodes crop n of BlazePose's landmarks ([N, 1, 1, 195] or [N, 195], pixels of a `size`-px
// crop) and pose flag ([N, ...] one value each). Throws std::invalid_argument when they do not
// fit together.
SinglePose decode_blazepose(const GraphTensor& landmarks, const GraphTensor& flag, int size, int n);

// Decodes crop n of the four heads (NHWC [N, H, W, C]: centre 1, heatmap 17, regress 34, offset
// 34 channels). Throws std::invalid_argument when the heads do not fit together.
SinglePoseKeypoints decode_singlepose(const GraphTensor& center, const GraphTensor& heatmap,
                                      const GraphTensor& regress, const GraphTensor& offset, int n);

class SinglePoseNetwork {
 public:
  // Throws std::runtime_error (naming the file and the fetch command) when it cannot be loaded.
  // options.input_node is set here.
  SinglePoseNetwork(SinglePoseModel model, const std::filesystem::path& model_json,
                    const RunnerOptions& options = {});

  SinglePoseModel model() const { return model_; }
  int input_size() const { return detect::input_size(model_); }
  Backend backend() const { return runner_->backend(); }

  // The heads for a batch of crops: NHWC [N, size, size, 3] float RGB 0..255, size =
  // input_size(). MoveNet: center, heatmap, regress, offset; BlazePose (fed the crops / 255, as
  // MediaPipe and @vladmandic/human feed it): landmarks [N, 1, 1, 195], pose flag [N, 1, 1, 1].
  // Valid until the next call.
  const std::vector<GraphTensor>& run_heads(const GraphTensor& crops);
  // The keypoints of every crop of the batch, run in passes of `largest_pass`, its halves ... 1
  // crops (8: 8, 4, 2, 1): the XNNPACK runtime builds itself per input shape (about 0.3 s) and
  // keeps the last 4, so whatever the number of people, these shapes are all it ever builds. A
  // crop's keypoints do not depend on the pass it is in (tests/detect/detect_golden_test.cpp).
  std::vector<SinglePose> run(const GraphTensor& crops, int largest_pass = kLargestPass);
  // The same for crops [first, first + count) of the batch, written to out[0, count).
  void run(const GraphTensor& crops, int first, int count, std::span<SinglePose> out,
           int largest_pass = kLargestPass);
  // The largest pass by default; a power of two up to kMaxPass.
  static constexpr int kLargestPass = 8, kMaxPass = 8;

 private:
  SinglePoseModel model_;
  std::unique_ptr<GraphRunner> runner_;
  std::vector<GraphTensor> heads_;  // reused from call to call
  GraphTensor pass_;                // the crops of one pass
  GraphTensor scaled_;              // BlazePose: the crops of one pass / 255
};

}  // namespace mocap::detect
