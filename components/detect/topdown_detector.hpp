#pragma once
// Top-down detection: person boxes from MB3-CenterNet at a low rate, the keypoints of each person
// from a single-person model (MoveNet Lightning or Thunder, BlazePose lite, full or heavy) on a
// crop around them, every crop of a frame in
// one forward pass. Between detector runs each person's next crop comes from their own keypoints
// (the square around them, moved by their last motion): the detector/tracker split of MediaPipe's
// pose pipeline and of rtmlib's PoseTracker. A person whose crop no longer shows one is dropped,
// and the detector then runs on the next frame to look for them and for newcomers. No cap on the
// number of people.
//
// Both cores: `workers` single-thread copies of the keypoint network share each frame's crops (a
// share each, the calling thread runs one), and on a frame where the person detector runs it runs
// on a helper thread while the calling thread does the crops of the people already followed
// (measured against one two-thread network in docs/detection-strategies.md).
//
// Live: with keypoint_every K > 1 a followed person gets a keypoint pass only every K frames;
// on the frames between, their keypoints are carried by sparse optical flow with a forward-
// backward check (keypoint_flow.hpp), and a person whose flow fails gets a crop at once.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "core/image_buffer.hpp"
#include "detect/centernet.hpp"
#include "detect/image_tensor.hpp"
#include "detect/keypoint_flow.hpp"
#include "detect/movenet_decoder.hpp"
#include "detect/ordered_workers.hpp"
#include "detect/person_boxes.hpp"
#include "detect/singlepose.hpp"

namespace mocap::detect {

struct TopDownOptions {
  SinglePoseModel pose_model = SinglePoseModel::lightning;
  // The person detector runs on frame 0, then every detect_every frames (1: every frame), and on
  // the frame after one that lost somebody.
  int detect_every = 10;
  // A re-run after a loss only when the detector last ran at least this many frames before (the
  // loss waits for it or for the scheduled run); 0: every loss, as before (file-cpu).
  int rerun_gap = 0;
  float min_box_score = 0.3f;  // CenterNet person score
  float box_overlap = 0.5f;    // detector boxes overlapping more are one (NMS)
  // The person detector on the whole frame stretched (1) or on this many square tiles of a wide
  // frame (person_proposals.hpp).
  int detector_tiles = 1;
  // With detector_tiles > 1: one more detector pass over the whole frame stretched, for the
  // people wider than the tiles' overlap (close-ups); all passes merged by NMS.
  bool detector_whole_frame = false;
  // With detector_tiles 1: CenterNet sees the frame at its own aspect (short side 512, long side
  // scaled alike to a multiple of 32: 512 × 896 for 1280 × 720; centernet_input_at_aspect)
  // instead of squeezed to 512 × 512, which shrinks a 16:9 frame's people to 0.40 of their width.
  // Costs the pixels' ratio in CenterNet's time (1.75× at 16:9), on its runs only.
  bool detector_aspect = false;
  // A detector box overlapping a followed person's box by more than this is that person.
  float followed_overlap = 0.3f;
  // On a detector run, each followed person is at most one detector box (the pairs overlapping
  // most matched first); a second box overlapping them is a newcomer and gets its own crop, so
  // that one of two people embracing or crossing, followed as one box, is looked for. Off: every
  // box overlapping a followed person's is that person.
  bool one_box_per_followed = false;
  // On a detector run, a followed person whose box overlaps two or more detector boxes (each by
  // more than followed_overlap) is that many people: two people embracing or crossing whom one
  // crop's landmarks span as one box. Their crop is set aside and each box gets its own crop.
  bool split_followed = false;
  float crop_padding = 1.25f;  // crop side = longer box side × this
  // A box shorter than small_box_height px (0: none) gets a crop of side longer box side ×
  // small_crop_padding instead: more context around a small person, whose detector box is
  // loose (upscaled to the model's input like every crop). 1.5 a priori: MediaPipe's
  // detection-to-ROI square is 1.25 × the diameter of the body's enclosing circle around the
  // hips, ~1.1-1.2 × a standing person's height, i.e. ~1.4-1.5 × the height.
  float small_box_height = 0.0f;
  float small_crop_padding = 1.5f;
  float min_keypoint_score = 0.3f;  // keypoints below are missing
  // A crop shows a person when at least min_keypoints keypoints pass and their mean score reaches
  // min_person_score.
  int min_keypoints = 6;
  float min_person_score = 0.35f;
  // Models with a pose-presence flag (BlazePose): the crop shows a person when the flag reaches
  // this instead (MediaPipe's threshold on it, 0.5); the keypoints kept are still those scoring
  // min_keypoint_score.
  float min_pose_presence = 0.5f;
  // Models with landmark presence (BlazePose): a posed person's box and their next crop span the
  // body landmarks whose presence reaches this (MediaPipe's 0.5), hidden or blurred legs
  // included, while the keypoints emitted are still those scoring min_keypoint_score. Above 1:
  // the box of the emitted keypoints, as for MoveNet.
  float box_landmark_presence = 0.5f;
  // The margins of the person's landmark box: true, from the body's proportions, cut to the
  // picture (posed_box); false, the keypoints' widening (12 % above, 6 % below and aside, not
  // cut), kept to measure the two against each other. The crop's box is the latter either way
  // (posed_crop_box).
  bool anatomical_landmark_box = true;
  // With the anatomical box: the head's margin is also at least kHeadAboveEyesPerEyeToShoulder ×
  // the eyes-to-shoulders height, so that it does not shrink with the landmarks' extent when the
  // legs are outside the picture (or hidden), which leaves eyes to hips.
  bool head_margin_from_shoulders = false;
  // A person the detector is sure of: a box scoring at least this is a person even when its
  // crop's keypoints fail the test above (blurred or crowded people); only the keypoints scoring
  // min_keypoint_score are kept, and the box is the detector's. Such a person is followed until
  // the next detector run, which keeps them only if it still finds them this sure. 0: off.
  float sure_box_score = 0.0f;
  // A newcomer (a detector box nobody followed) is a person only when their posed box overlaps
  // the detector's box by at least this IoU (0: off): a pose whose box disagrees with the box it
  // was cropped for is on a neighbour or a mix of people in a row. 0.5 a priori: the IoU at which
  // the evaluation and the detector's NMS call two boxes one person.
  float newcomer_agreement = 0.0f;
  float duplicate_overlap = 0.6f;  // people whose boxes overlap more are one
  // Two finds of a frame with at least 3 keypoints in common are one person only when their
  // keypoint similarity (COCO's OKS, person_boxes.hpp) reaches this, however much their boxes
  // overlap, so that two people embracing or crossing stay two; finds with fewer keypoints in
  // common are compared by duplicate_overlap. 0: off (box overlap or most keypoints within 5 % of
  // the person's size, as before). 0.9 a priori: the OKS threshold of the top-down pose
  // estimators' duplicate removal (HRNet's and MMPose's COCO test settings, oks_thr 0.9).
  float duplicate_similarity = 0.0f;
  // The network runtime of both networks and their threads (graph_runner.hpp: XNNPACK's are each
  // network's own, 0 meaning one; cv::dnn's are process-wide, 0 its default).
  Backend backend = Backend::automatic;
  int threads = 0;
  // Copies of the keypoint network, each on its own thread (the calling thread runs the first);
  // with more than one, `threads` 0 means 1 per copy.
  int workers = 1;
  // Crops per forward pass of the keypoint network at most (1, 2, 4 or 8): a frame's crops go in
  // passes of this, its halves, ... 1. The people found do not depend on it; the time does
  // (smaller passes keep a pass's activations in the core's cache: measured in
  // docs/detection-strategies.md, "Both cores for the file default").
  int crops_per_pass = 2;
  // A followed person's keypoints come from the keypoint network every keypoint_every frames
  // (1: every frame) and are carried by optical flow in between: a keypoint's flow counts when
  // flowed back it lands within max(1 px, flow_error x the person's box height) of where it
  // started; with at least min_keypoints such, the person (box and keypoints whose flow failed)
  // moves by their median motion, the others move by their own flow; with fewer the person gets a
  // keypoint pass instead.
  int keypoint_every = 1;
  float flow_error = 0.03f;
  // With keypoint_every K > 1: the people posed on one frame get their next passes spread over
  // the K frames after it (spread_keypoint_passes); false: all on the K-th (kept to measure).
  bool spread_keypoint_passes = true;
  // Live: the person detector runs on a thread of its own, on a copy of the frame it was due on,
  // while the frames go on with the people already followed; its boxes are taken in on the first
  // frame after the run ends, compared with where the people followed were on the run's frame.
  // A frame with people to follow then never waits for the detector (a run costs several frame
  // periods of a 25 fps camera), at the price of newcomers found a few frames later from boxes a
  // few frames old (the crop's padding absorbs that motion). What is found depends on timing:
  // off for files. Runs start every detect_every frames and after a frame that lost somebody,
  // when none is running; a frame with nobody followed runs the detector itself (or waits for
  // the run going on): it has nothing else to do.
  bool detector_in_background = false;
};

// The person test of one crop's answer: MoveNet's keypoints (at least min_keypoints scoring
// min_keypoint_score, their mean reaching min_person_score) or, from a model with a presence flag
// (BlazePose), the flag reaching min_pose_presence with two keypoints passing to span a box.
// `score` is the passing keypoints' mean score, or the flag.
struct CropVerdict {
  int passing = 0;
  float score = 0;
  bool posed = false;
};
CropVerdict judge_crop(const SinglePose& pose, const TopDownOptions& options);

// Which followed person each detector box is: per detection, the index of the followed box
// (their predicted box) it overlaps by IoU > min_overlap, or -1 (a newcomer). With `one_each`
// each followed person is at most one box, the pairs overlapping most matched first (greedy, as
// SORT-like trackers associate): a second box on them is somebody else; without, every box
// overlapping them is them (the first such person's).
std::vector<int> followed_boxes(std::span<const Box2D> followed,
                                std::span<const Detection> detections, float min_overlap,
                                bool one_each);

// The square a box's crop is cut from: its longer side × crop_padding, or × small_crop_padding
// for a box shorter than small_box_height.
SquareRegion crop_region(const Box2D& box, const TopDownOptions& options);

// The box of a posed person cut from `region` of a `frame_width` × `frame_height` picture, in
// frame pixels. With BlazePose (and box_landmark_presence <= 1) that of the body landmarks whose
// presence reaches box_landmark_presence, when at least two do, grown by kLandmarkBoxMargins (with
// anatomical_landmark_box) and cut to the picture; otherwise that of the keypoints scoring
// min_keypoint_score widened as keypoint_box does by 0.12 (the top of the head above the eyes).
Box2D posed_box(const SinglePose& pose, const SquareRegion& region, const TopDownOptions& options,
                int frame_width, int frame_height);

// The box a posed person's next crop is cut around: that of the same points as posed_box's,
// always widened by 0.12 as keypoint_box does and not cut to the picture. Wider than BlazePose's
// person box on purpose: a crop cut tight to the last frame's landmarks loses the feet of a
// moving person, their presence falls, and box and crop shrink frame after frame (measured in
// docs/detection-strategies.md, "Boxes from the body's proportions").
Box2D posed_crop_box(const SinglePose& pose, const SquareRegion& region,
                     const TopDownOptions& options);

// How far a person reaches beyond BlazePose's landmarks, as shares of the landmarks' extent (of a
// standing person: eyes to soles). The feet's landmarks (heels, toes) lie on the soles: nothing
// below. The top of the head lies 105-110 mm above the eyes at an eye height of 1505-1630 mm
// (British women and men, 50th percentile, stature minus eye height in Pheasant's tables): 0.07.
// Aside, the deltoids reach (465 - 400) / 2 = 32 mm beyond the acromia (bideltoid against
// biacromial breadth, British men), the shoulder landmark sitting about as far inside them:
// 0.03 (50 mm of 1630). Chosen from these tables before any run, not fitted.
inline constexpr BoxMargins kLandmarkBoxMargins{0.07f, 0.0f, 0.03f};

// The top of the head above the eyes as a share of the eyes' height above the shoulders (the
// acromion): 110 / (1630 - 1425) = 0.54 for British men, 105 / (1505 - 1310) = 0.54 for women
// (50th percentiles, Pheasant's tables as above; shoulder height there). A priori, not fitted.
inline constexpr float kHeadAboveEyesPerEyeToShoulder = 0.54f;

// What the last detect() did with each box of the frame, for diagnosis (mocap-bench-detect
// --diagnose: which rule dropped a person the detector had proposed).
struct TopDownTrace {
  enum class Fate : std::uint8_t {
    rejected,              // the crop's keypoints failed the person test
    kept,                  // a person of the frame
    duplicate_box,         // dropped: box overlap with a kept person (duplicate_overlap)
    duplicate_keypoints,   // dropped: most keypoints on a kept person's
    duplicate_similarity,  // dropped: keypoint similarity (duplicate_similarity)
    split                  // set aside: a followed box over several detector boxes
  };
  struct Crop {
    Box2D box;              // the box it was cut around
    bool newcomer = false;  // a detector box nobody followed (else a followed person's)
    Box2D found;            // the person's box when it passed (empty otherwise)
    Fate fate = Fate::rejected;
  };
  bool detector_ran = false;
  std::vector<Detection> detections;  // the detector's boxes (after NMS), when it ran
  // Per detection: the crop of the followed person it was taken for (its box overlapped theirs
  // by more than followed_overlap), or -1 when it got a crop of its own (newcomer), or -2 when
  // it was taken for a person carried by optical flow.
  std::vector<int> taken_for;
  std::vector<Crop> crops;
};

// Where the time of detect() went, summed over the frames since the detector was made (seconds,
// wall clock). CenterNet runs on a helper thread when there are several workers, then overlapping
// the keypoint passes.
struct TopDownProfile {
  long long frames = 0, detector_runs = 0, crops = 0;
  double total = 0;           // detect() from call to return
  double centernet = 0;       // the person detector: frame stretched, forward, decoding, NMS
  double centernet_wait = 0;  // the calling thread running it or waiting for its helper
  double crop_fill = 0;       // crops cut out of the frame
  double keypoints = 0;   // keypoint passes on the calling thread, waiting for the helpers included
  long long carried = 0;  // people carried by optical flow instead of a keypoint pass
  long long flow_failed = 0;  // people due to be carried whose flow failed (they got a crop)
  double flow = 0;            // grey pyramids and optical flow
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
  // With detector_in_background: waits for the person detector's run in progress, if any; the
  // next detect() takes its boxes in.
  void wait_for_detector();
  // Runs both networks once on blank inputs of every shape they will get (XNNPACK builds a
  // runtime per shape, about 0.3 s each), so that a live source's first frames are not late.
  void warm_up();

  const TopDownOptions& options() const { return options_; }
  // The runtime the networks run on (`automatic` resolved).
  Backend backend() const { return poses_.front()->backend(); }
  // Frames on which the person detector ran, of all frames seen.
  long long detector_runs() const { return profile_.detector_runs; }
  const TopDownProfile& profile() const { return profile_; }
  // What the last detect() did with each box (cheap: kept on every frame).
  const TopDownTrace& trace() const { return trace_; }

 private:
  struct Followed {
    Box2D box;             // the box their next crop is cut around (posed_crop_box)
    float vx = 0, vy = 0;  // motion of the box centre per frame
    MovenetPerson person;  // their keypoints in the last frame
    int carried = 0;       // frames since their last keypoint pass
    float box_score = 0;   // the detector's score of them at its last run (0: not found by it)
    long long id = -1;     // the same from frame to frame while they are followed
  };
  // A person found in this frame, how many frames their keypoints have been carried (0: a
  // keypoint pass), the detector's score of them, and whether their keypoints passed the person
  // test (or the detector's score alone kept them).
  struct Found {
    MovenetPerson person;
    Box2D follow;  // the box of their next crop
    int carried = 0;
    float box_score = 0;
    bool posed = true;
    int crop = -1;      // the crop of the frame it came from (-1: carried by optical flow)
    long long id = -1;  // the followed person it continues (-1: a newcomer's crop)
  };
  // The person detector on `frame` (uses boxes_ and image_: one caller at a time).
  std::vector<Detection> propose(const ImageBuffer& frame);
  // propose(), timed into the profile.
  std::vector<Detection> find_boxes(const ImageBuffer& frame);
  // The detector's boxes of this frame, found beside the crops of the people followed (`boxes`,
  // cut meanwhile when there are helpers): how many of `boxes` were cropped.
  std::size_t find_boxes_beside_crops(const ImageBuffer& frame, std::span<const Box2D> boxes,
                                      std::vector<Detection>& detections);
  // detector_in_background: starts a run on a copy of `frame`; takes a finished run's boxes
  // into `detections` (false when none finished since the last call).
  void start_detector(const ImageBuffer& frame);
  bool finished_detector(std::vector<Detection>& detections);
  // The detector's boxes against the people followed (`boxes`' first `followed`, their crops'
  // boxes; `found`, those carried by flow): the detector scores of the followed, and a crop box
  // appended to `boxes` for every newcomer.
  void take_detections(const std::vector<Detection>& detections, std::size_t followed,
                       const std::vector<Found>& found, std::vector<Box2D>& boxes);
  // Where the followed person `id` was on the frame the background run looked at (their box
  // then, which the run's boxes are compared with), else `now`.
  Box2D at_detector_frame(long long id, const Box2D& now) const;
  // The next frame's followed people: each person kept, moved by how far their nearest
  // predecessor moved.
  std::vector<Followed> follow(const std::vector<MovenetPerson>& people,
                               const std::vector<Found>& found,
                               const std::vector<std::size_t>& kept);
  // With keypoint_every K: the people posed on this frame are spread over the next K frames'
  // keypoint passes, each to the frame the fewest are due on (a sooner pass, never a later one),
  // so that a frame's passes stay about people / K instead of every person's at once every K
  // frames after a detector run (a live frame that long is late and the source's next dropped).
  void spread_keypoint_passes(std::vector<Followed>& next) const;
  // Keypoints of a crop for each box, appended to found_ (regions_ gets their squares), the
  // crops shared by the first `copies` copies of the keypoint network.
  // box_scores_ holds, per box of the frame, the detector's score of it.
  void add_crops(const ImageBuffer& frame, std::span<const Box2D> boxes, int copies);
  // Keypoints of crops_[0, count) into found_[first, first + count), on `copies` copies at once.
  void run_keypoints(int first, int count, int copies);
  // People of the crops of this frame, appended to `found`.
  void people_found(const ImageBuffer& frame, std::vector<Found>& found) const;
  // Each crop of the frame and what became of it into trace_ (`why`: per find of `found`).
  void record_crops(const std::vector<Found>& found, const std::vector<DuplicateRule>& why);
  // The followed people due no keypoint pass moved into this frame by optical flow, appended to
  // `out`; marks in carried_ which were (the others need a crop).
  void carry(std::vector<Found>& out);

  TopDownOptions options_;
  std::vector<std::unique_ptr<SinglePoseNetwork>> poses_;  // copy 0 runs on the calling thread
  std::unique_ptr<CenternetNetwork> boxes_;
  std::filesystem::path centernet_json_;          // to make boxes_ again at another frame's aspect
  std::unique_ptr<OrderedWorkers<int>> helpers_;  // workers - 1 threads; none with one worker
  GraphTensor image_, crops_;  // the networks' inputs, reused from frame to frame
  std::vector<SquareRegion> regions_;
  std::vector<Box2D> crop_boxes_;       // per crop of the frame: the box it was cut around
  std::vector<float> box_scores_;       // per box of the frame: the detector's score of it
  std::vector<long long> box_ids_;      // per box: the followed person's id (-1: a newcomer)
  std::vector<std::uint8_t> newcomer_;  // per box of the frame: a detector box nobody followed
  std::vector<std::uint8_t> split_;     // per box: a followed box split (split_followed)
  std::vector<SinglePose> found_;
  std::vector<Followed> followed_;
  std::unique_ptr<KeypointFlow> flow_;  // with keypoint_every > 1
  std::vector<FlowPoint> flow_from_, flow_to_;
  std::vector<float> flow_limit_, flow_dx_, flow_dy_;
  std::vector<std::uint8_t> flow_ok_, carried_;
  long long frame_ = 0;
  long long detector_started_ = 0;     // the frame its last background run started on
  long long last_detector_frame_ = 0;  // the last frame the detector ran on (rerun_gap)
  long long next_id_ = 0;
  // The people followed on the frame the background run looks at: their ids and boxes.
  std::vector<std::pair<long long, Box2D>> detector_frame_people_;
  bool lost_someone_ = false;
  TopDownProfile profile_;
  TopDownTrace trace_;
  // The background person detector (detector_in_background): its run's boxes and seconds. Last,
  // so that it is stopped (its run finished) before what the run uses is destroyed.
  struct BackgroundBoxes {
    std::vector<Detection> detections;
    double seconds = 0;
  };
  std::unique_ptr<OrderedWorkers<BackgroundBoxes>> background_;
};

}  // namespace mocap::detect
