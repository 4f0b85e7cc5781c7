#pragma once
// Top-down detection: person boxes from MB3-CenterNet at a low rate, the keypoints of each person
// from MoveNet single-pose (Lightning or Thunder) on a crop around them, every crop of a frame in
// one forward pass. Between detector runs each person's next crop comes from their own keypoints
// (the square around them, moved by their last motion): the detector/tracker split of MediaPipe's
// pose pipeline and of rtmlib's PoseTracker. A person whose crop no longer shows one is dropped,
// and the detector then runs on the next frame to look for them and for newcomers. No cap on the
// number of people.

#include <filesystem>
#include <memory>
#include <vector>

#include "core/image_buffer.hpp"
#include "detect/centernet.hpp"
#include "detect/movenet_decoder.hpp"
#include "detect/singlepose.hpp"

namespace mocap::detect {

struct TopDownOptions {
  SinglePoseModel pose_model = SinglePoseModel::lightning;
  // The person detector runs on frame 0, then every detect_every frames (1: every frame), and on
  // the frame after one that lost somebody.
  int detect_every = 10;
  float min_box_score = 0.3f;  // CenterNet person score
  float box_overlap = 0.5f;    // detector boxes overlapping more are one (NMS)
  // The person detector on the whole frame stretched (1) or on this many square tiles of a wide
  // frame (person_proposals.hpp).
  int detector_tiles = 1;
  // A detector box overlapping a followed person's box by more than this is that person.
  float followed_overlap = 0.3f;
  float crop_padding = 1.25f;       // crop side = longer box side × this
  float min_keypoint_score = 0.3f;  // keypoints below are missing
  // A crop shows a person when at least min_keypoints keypoints pass and their mean score reaches
  // min_person_score.
  int min_keypoints = 6;
  float min_person_score = 0.35f;
  float duplicate_overlap = 0.6f;  // people whose boxes overlap more are one
  // The network runtime of both networks and their threads (graph_runner.hpp: XNNPACK's are each
  // network's own, 0 meaning one; cv::dnn's are process-wide, 0 its default).
  Backend backend = Backend::automatic;
  int threads = 0;
};

class TopDownDetector {
 public:
  // Throws std::runtime_error when a model cannot be loaded (naming it and the fetch command).
  TopDownDetector(const TopDownOptions& options, const std::filesystem::path& pose_model_json,
                  const std::filesystem::path& centernet_json);
  ~TopDownDetector();

  // The people in this frame, best first; frames must come in order (the crops follow people).
  std::vector<MovenetPerson> detect(const ImageBuffer& frame);
  // Forget the people followed so far (a new video).
  void reset();

  const TopDownOptions& options() const { return options_; }
  // The runtime the networks run on (`automatic` resolved).
  Backend backend() const { return pose_.backend(); }
  // Frames on which the person detector ran, of all frames seen.
  long long detector_runs() const { return detector_runs_; }

 private:
  struct Followed {
    Box2D box;             // the person's box in the last frame
    float vx = 0, vy = 0;  // motion of the box centre per frame
  };
  std::vector<Detection> find_boxes(const ImageBuffer& frame);
  std::vector<MovenetPerson> pose(const ImageBuffer& frame, const std::vector<Box2D>& boxes);

  TopDownOptions options_;
  SinglePoseNetwork pose_;
  std::unique_ptr<CenternetNetwork> boxes_;
  GraphTensor image_, crops_;  // the networks' inputs, reused from frame to frame
  std::vector<Followed> followed_;
  long long frame_ = 0, detector_runs_ = 0;
  bool lost_someone_ = false;
};

}  // namespace mocap::detect
