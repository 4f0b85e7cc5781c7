#include "detect/topdown_detector.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "detect/image_tensor.hpp"
#include "detect/person_boxes.hpp"
#include "detect/person_proposals.hpp"

namespace mocap::detect {
namespace {

// How far above the eyes the head reaches, as a share of the keypoints' extent.
constexpr float kHeadMargin = 0.12f;

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void check(const TopDownOptions& o) {
  if (o.detect_every < 1) throw std::invalid_argument("detect_every must be at least 1");
  if (o.rerun_gap < 0) throw std::invalid_argument("rerun_gap must be >= 0");
  if (!(o.crop_padding >= 1.0f && o.crop_padding <= 4.0f))
    throw std::invalid_argument("crop_padding must lie in [1, 4]");
  if (o.min_keypoints < 1 || o.min_keypoints > kMovenetKeypoints)
    throw std::invalid_argument("min_keypoints must lie in [1, 17]");
  if (o.detector_tiles < 1) throw std::invalid_argument("detector_tiles must be at least 1");
  if (!(o.sure_box_score >= 0.0f && o.sure_box_score <= 1.0f))
    throw std::invalid_argument("sure_box_score must lie in [0, 1] (0: off)");
  if (!(o.newcomer_agreement >= 0.0f && o.newcomer_agreement <= 1.0f))
    throw std::invalid_argument("newcomer_agreement must lie in [0, 1] (0: off)");
  if (!(o.min_pose_presence >= 0.0f && o.min_pose_presence <= 1.0f))
    throw std::invalid_argument("min_pose_presence must lie in [0, 1]");
  if (!(o.small_box_height >= 0.0f) ||
      !(o.small_crop_padding >= 1.0f && o.small_crop_padding <= 4.0f))
    throw std::invalid_argument("small_box_height must be >= 0 and small_crop_padding in [1, 4]");
  if (o.workers < 1 || o.workers > 16) throw std::invalid_argument("workers must lie in [1, 16]");
  if (o.crops_per_pass < 1 || o.crops_per_pass > SinglePoseNetwork::kMaxPass ||
      (o.crops_per_pass & (o.crops_per_pass - 1)) != 0)
    throw std::invalid_argument("crops_per_pass must be 1, 2, 4 or 8");
  if (o.keypoint_every < 1) throw std::invalid_argument("keypoint_every must be at least 1");
  if (!(o.followed_overlap > 0.0f && o.followed_overlap < 1.0f))
    throw std::invalid_argument("followed_overlap must lie in (0, 1)");
  if (!(o.duplicate_similarity >= 0.0f && o.duplicate_similarity <= 1.0f))
    throw std::invalid_argument("duplicate_similarity must lie in [0, 1] (0: off)");
  if (!(o.flow_error > 0.0f && o.flow_error <= 1.0f))
    throw std::invalid_argument("flow_error must lie in (0, 1]");
}

RunnerOptions runner_options(const TopDownOptions& o) {
  RunnerOptions r;
  r.backend = o.backend;
  // Several copies of a network each on a pool of all cores would fight over them.
  r.threads = o.threads == 0 && o.workers > 1 ? 1 : o.threads;
  return r;
}

Box2D moved(const Box2D& box, float dx, float dy) {
  return {box.x + dx, box.y + dy, box.width, box.height};
}

// The median of `values` (reordered); `values` is not empty.
float median(std::vector<float>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Waits for the `count` oldest jobs of `helpers`, then rethrows the first error (`error`, then
// theirs): jobs refer to the caller's locals, so none may still run when it unwinds.
void join(OrderedWorkers<int>& helpers, int count, std::exception_ptr error) {
  for (int i = 0; i < count; ++i) {
    try {
      helpers.next(true);
    } catch (...) {
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

// `image` with its own tightly packed copy of the pixels.
ImageBuffer packed_copy(const ImageBuffer& image) {
  ImageBuffer copy(image.width(), image.height(), image.format());
  const std::size_t row = static_cast<std::size_t>(image.width()) *
                          static_cast<std::size_t>(bytes_per_pixel(image.format()));
  std::byte* to = copy.pixels_for_writing().data();
  for (int y = 0; y < image.height(); ++y)
    std::memcpy(to + row * static_cast<std::size_t>(y),
                image.data() + static_cast<std::size_t>(image.stride()) * y, row);
  return copy;
}

}  // namespace

CropVerdict judge_crop(const SinglePose& pose, const TopDownOptions& options) {
  CropVerdict v;
  float sum = 0;
  for (const auto& [y, x, score] : pose.keypoints) {
    if (score < options.min_keypoint_score) continue;
    ++v.passing;
    sum += score;
  }
  v.score = v.passing > 0 ? sum / static_cast<float>(v.passing) : 0.0f;
  if (pose.presence == kNoPresence) {
    v.posed = v.passing >= options.min_keypoints && v.score >= options.min_person_score;
  } else {
    v.score = pose.presence;
    v.posed = pose.presence >= options.min_pose_presence && v.passing >= 2;
  }
  return v;
}

std::vector<int> followed_boxes(std::span<const Box2D> followed,
                                std::span<const Detection> detections, float min_overlap,
                                bool one_each) {
  std::vector<int> owner(detections.size(), -1);
  const float least = min_overlap;
  if (!one_each) {
    // Every box overlapping a followed person's is theirs.
    for (std::size_t d = 0; d < detections.size(); ++d)
      for (std::size_t i = 0; i < followed.size() && owner[d] < 0; ++i)
        if (iou(followed[i], detections[d].box) > least) owner[d] = static_cast<int>(i);
    return owner;
  }
  struct Pair {
    float overlap;
    std::size_t d, i;
  };
  std::vector<Pair> pairs;
  for (std::size_t d = 0; d < detections.size(); ++d)
    for (std::size_t i = 0; i < followed.size(); ++i)
      if (const float v = iou(followed[i], detections[d].box); v > least)
        pairs.push_back({v, d, i});
  std::stable_sort(pairs.begin(), pairs.end(),
                   [](const Pair& a, const Pair& b) { return a.overlap > b.overlap; });
  std::vector<std::uint8_t> taken(followed.size(), 0);
  for (const Pair& p : pairs) {
    if (owner[p.d] >= 0 || taken[p.i]) continue;
    owner[p.d] = static_cast<int>(p.i);
    taken[p.i] = 1;
  }
  return owner;
}

SquareRegion crop_region(const Box2D& box, const TopDownOptions& options) {
  const bool small = box.height < options.small_box_height;
  return square_around(box, small ? options.small_crop_padding : options.crop_padding);
}

namespace {

// BlazePose's landmarks (MediaPipe's order) that place the head above the shoulders.
constexpr int kLeftEye = 2, kRightEye = 5, kLeftShoulder = 11, kRightShoulder = 12;

// How far the eyes lie above the shoulders in the crop (its share of the crop's side), or 0 when
// a landmark of either pair is absent or the shoulders are not below the eyes.
float eyes_above_shoulders(const SinglePose& pose, float min_presence) {
  if (pose.body_landmarks <= kRightShoulder) return 0;
  const auto& b = pose.body;
  for (const int k : {kLeftEye, kRightEye, kLeftShoulder, kRightShoulder})
    if (b[static_cast<std::size_t>(k)][2] < min_presence) return 0;
  const float eyes = (b[kLeftEye][0] + b[kRightEye][0]) / 2;
  const float shoulders = (b[kLeftShoulder][0] + b[kRightShoulder][0]) / 2;
  return std::max(0.0f, shoulders - eyes);
}

// The points a posed person's boxes span, in frame pixels: BlazePose's landmarks whose presence
// reaches box_landmark_presence when at least two do, else the keypoints scoring
// min_keypoint_score. Returns how many, and whether they are landmarks.
std::pair<std::size_t, bool> posed_points(const SinglePose& pose, const SquareRegion& region,
                                          const TopDownOptions& options,
                                          std::array<Keypoint2D, kBlazePoseBody>& points) {
  const auto in_frame = [&](const std::array<float, 3>& point) {
    const auto& [y, x, score] = point;
    return Keypoint2D{region.cx - region.side / 2 + x * region.side,
                      region.cy - region.side / 2 + y * region.side, score};
  };
  std::size_t count = 0;
  if (options.box_landmark_presence <= 1.0f) {
    const auto body = std::span(pose.body).first(static_cast<std::size_t>(pose.body_landmarks));
    for (const auto& landmark : body)
      if (landmark[2] >= options.box_landmark_presence) points[count++] = in_frame(landmark);
    if (count >= 2) return {count, true};
  }
  // Fewer than two landmarks span no box: the kept keypoints' then (MoveNet's always).
  count = 0;
  for (const auto& keypoint : pose.keypoints)
    if (keypoint[2] >= options.min_keypoint_score) points[count++] = in_frame(keypoint);
  return {count, false};
}

}  // namespace

Box2D posed_box(const SinglePose& pose, const SquareRegion& region, const TopDownOptions& options,
                int frame_width, int frame_height) {
  std::array<Keypoint2D, kBlazePoseBody> points{};
  const auto [count, landmarks] = posed_points(pose, region, options, points);
  const auto present = std::span(points).first(count);
  if (landmarks && options.anatomical_landmark_box) {
    Box2D box = points_box(present, kLandmarkBoxMargins);
    if (options.head_margin_from_shoulders) {
      // The head's margin from the head's own size when that is more: legs out of the picture
      // shorten the landmarks' extent, not the head.
      const Box2D bare = points_box(present, {});
      const float margin = kLandmarkBoxMargins.top * std::max(bare.width, bare.height);
      const float head = kHeadAboveEyesPerEyeToShoulder * region.side *
                         eyes_above_shoulders(pose, options.box_landmark_presence);
      if (head > margin)
        box = {box.x, box.y - (head - margin), box.width, box.height + head - margin};
    }
    return clip_box(box, static_cast<float>(frame_width), static_cast<float>(frame_height));
  }
  return keypoint_box(present, kHeadMargin);
}

Box2D posed_crop_box(const SinglePose& pose, const SquareRegion& region,
                     const TopDownOptions& options) {
  std::array<Keypoint2D, kBlazePoseBody> points{};
  const auto [count, landmarks] = posed_points(pose, region, options, points);
  return keypoint_box(std::span(points).first(count), kHeadMargin);
}

TopDownDetector::TopDownDetector(const TopDownOptions& options,
                                 const std::filesystem::path& pose_model_json,
                                 const std::filesystem::path& centernet_json)
    : options_((check(options), options)),
      boxes_(std::make_unique<CenternetNetwork>(centernet_json, runner_options(options))),
      centernet_json_(centernet_json) {
  for (int i = 0; i < options_.workers; ++i)
    poses_.push_back(std::make_unique<SinglePoseNetwork>(options_.pose_model, pose_model_json,
                                                         runner_options(options_)));
  if (options_.workers > 1) helpers_ = std::make_unique<OrderedWorkers<int>>(options_.workers - 1);
  if (options_.keypoint_every > 1) flow_ = std::make_unique<KeypointFlow>();
  if (options_.detector_in_background)
    background_ = std::make_unique<OrderedWorkers<BackgroundBoxes>>(1);
}

TopDownDetector::~TopDownDetector() = default;

void TopDownDetector::reset() {
  // A background run on the last video's frame is forgotten, whatever became of it.
  if (background_ && background_->pending() > 0) {
    background_->wait_oldest();
    try {
      background_->next(false);
    } catch (...) {
    }
  }
  followed_.clear();
  frame_ = 0;
  detector_started_ = 0;
  last_detector_frame_ = 0;
  detector_frame_people_.clear();
  lost_someone_ = false;
  if (flow_) flow_->reset();
}

void TopDownDetector::warm_up() {
  wait_for_detector();  // it uses the person detector's network and input
  // With detector_aspect the network for the frame's aspect is made on the first frame.
  image_batch(image_, 1, boxes_->input_height(), boxes_->input_width());
  boxes_->run(image_);
  // The shapes SinglePoseNetwork::run passes: crops_per_pass, its halves, ... 1 crops, on every
  // copy.
  const int copies = static_cast<int>(poses_.size());
  const int size = poses_.front()->input_size();
  for (int pass = options_.crops_per_pass; pass >= 1; pass /= 2) {
    image_batch(crops_, pass * copies, size, size);
    found_.resize(static_cast<std::size_t>(pass * copies));
    run_keypoints(0, pass * copies, copies);
  }
  found_.clear();
}

std::vector<Detection> TopDownDetector::propose(const ImageBuffer& frame) {
  if (options_.detector_aspect && options_.detector_tiles == 1) {
    // The network for this frame's aspect (made again only when the frame's shape changes).
    const auto [height, width] = centernet_input_at_aspect(frame.width(), frame.height());
    if (boxes_->input_height() != height || boxes_->input_width() != width)
      boxes_ = std::make_unique<CenternetNetwork>(centernet_json_, height, width,
                                                  runner_options(options_));
  }
  return propose_people(*boxes_, frame,
                        {options_.min_box_score, options_.box_overlap, options_.detector_tiles,
                         options_.detector_whole_frame},
                        image_);
}

std::vector<Detection> TopDownDetector::find_boxes(const ImageBuffer& frame) {
  const auto start = Clock::now();
  std::vector<Detection> found = propose(frame);
  ++profile_.detector_runs;
  profile_.centernet += seconds_since(start);
  return found;
}

std::size_t TopDownDetector::find_boxes_beside_crops(const ImageBuffer& frame,
                                                     std::span<const Box2D> boxes,
                                                     std::vector<Detection>& detections) {
  if (!helpers_) {
    const auto running = Clock::now();
    detections = find_boxes(frame);
    profile_.centernet_wait += seconds_since(running);
    return 0;
  }
  // The person detector on a helper, the followed people's crops here meanwhile.
  helpers_->submit([&](int) {
    detections = find_boxes(frame);
    return 0;
  });
  std::exception_ptr error;
  try {
    add_crops(frame, boxes, 1);
  } catch (...) {
    error = std::current_exception();
  }
  const auto waiting = Clock::now();
  join(*helpers_, 1, error);
  profile_.centernet_wait += seconds_since(waiting);
  return boxes.size();
}

void TopDownDetector::start_detector(const ImageBuffer& frame) {
  // A copy: the caller may reuse the frame's memory while the run goes on.
  auto copy = std::make_shared<ImageBuffer>(packed_copy(frame));
  background_->submit([this, copy](int) {
    const auto start = Clock::now();
    BackgroundBoxes run{propose(*copy), 0};
    run.seconds = seconds_since(start);
    return run;
  });
  detector_started_ = frame_;
  detector_frame_people_.clear();
  for (const Followed& f : followed_) detector_frame_people_.emplace_back(f.id, f.box);
}

Box2D TopDownDetector::at_detector_frame(long long id, const Box2D& now) const {
  if (!options_.detector_in_background) return now;
  for (const auto& [seen, box] : detector_frame_people_)
    if (seen == id) return box;
  return now;
}

bool TopDownDetector::finished_detector(std::vector<Detection>& detections) {
  if (!background_) return false;
  std::optional<BackgroundBoxes> run = background_->next(false);
  if (!run) return false;
  detections = std::move(run->detections);
  ++profile_.detector_runs;
  profile_.centernet += run->seconds;
  return true;
}

void TopDownDetector::wait_for_detector() {
  if (!background_ || background_->pending() == 0) return;
  const auto waiting = Clock::now();
  background_->wait_oldest();
  profile_.centernet_wait += seconds_since(waiting);
}

void TopDownDetector::run_keypoints(int first, int count, int copies) {
  copies = std::clamp(copies, 1, std::max(count, 1));
  const std::span<SinglePose> out(found_.data() + first, static_cast<std::size_t>(count));
  // Copy c takes crops [count c / copies, count (c + 1) / copies).
  const auto share = [&](int c) {
    const int begin = count * c / copies, end = count * (c + 1) / copies;
    poses_[static_cast<std::size_t>(c)]->run(crops_, begin, end - begin,
                                             out.subspan(static_cast<std::size_t>(begin)),
                                             options_.crops_per_pass);
  };
  for (int c = 1; c < copies; ++c)
    helpers_->submit([&share, c](int) {
      share(c);
      return 0;
    });
  std::exception_ptr error;
  try {
    share(0);
  } catch (...) {
    error = std::current_exception();
  }
  if (copies > 1) join(*helpers_, copies - 1, error);
  if (error) std::rethrow_exception(error);
}

void TopDownDetector::add_crops(const ImageBuffer& frame, std::span<const Box2D> boxes,
                                int copies) {
  if (boxes.empty()) return;
  auto start = Clock::now();
  const int count = static_cast<int>(boxes.size());
  const int size = poses_.front()->input_size();
  image_batch(crops_, count, size, size);
  const int first = static_cast<int>(found_.size());
  for (int i = 0; i < count; ++i) {
    crop_boxes_.push_back(boxes[static_cast<std::size_t>(i)]);
    regions_.push_back(crop_region(crop_boxes_.back(), options_));
    fill_region(frame, regions_.back(), crops_, i);
  }
  found_.resize(found_.size() + boxes.size());
  profile_.crop_fill += seconds_since(start);
  start = Clock::now();
  run_keypoints(first, count, copies);
  profile_.keypoints += seconds_since(start);
}
void TopDownDetector::people_found(const ImageBuffer& frame, std::vector<Found>& found) const {
  for (std::size_t i = 0; i < found_.size(); ++i) {
    const SquareRegion& r = regions_[i];
    MovenetPerson person;
    for (int k = 0; k < kMovenetKeypoints; ++k) {
      const auto& [y, x, score] = found_[i].keypoints[k];
      person.keypoints[k] =
          score >= options_.min_keypoint_score
              ? Keypoint2D{r.cx - r.side / 2 + x * r.side, r.cy - r.side / 2 + y * r.side, score}
              : Keypoint2D{std::nanf(""), std::nanf(""), 0.0f};
    }
    const CropVerdict verdict = judge_crop(found_[i], options_);
    person.score = verdict.score;
    if (split_[i]) continue;  // split into the detector's boxes (split_followed)
    const float box_score = box_scores_[i];
    const bool agrees = options_.newcomer_agreement <= 0 || !newcomer_[i] ||
                        iou(posed_box(found_[i], r, options_, frame.width(), frame.height()),
                            crop_boxes_[i]) >= options_.newcomer_agreement;
    const bool posed = verdict.posed && agrees;
    const bool sure = options_.sure_box_score > 0 && box_score >= options_.sure_box_score;
    if (!posed && !sure) continue;
    // Keypoints too unsure to outline the person: the detector's box does.
    person.box =
        posed ? posed_box(found_[i], r, options_, frame.width(), frame.height()) : crop_boxes_[i];
    const Box2D follow = posed ? posed_crop_box(found_[i], r, options_) : crop_boxes_[i];
    found.push_back({person, follow, 0, box_score, posed, static_cast<int>(i), box_ids_[i]});
  }
}

void TopDownDetector::carry(std::vector<Found>& out) {
  carried_.assign(followed_.size(), 0);
  if (!flow_ || !flow_->ready()) return;
  const auto start = Clock::now();
  const auto due_carry = [&](const Followed& f) { return f.carried + 1 < options_.keypoint_every; };
  flow_from_.clear();
  flow_limit_.clear();
  for (const Followed& f : followed_) {
    if (!due_carry(f)) continue;
    const float limit = std::max(1.0f, options_.flow_error * f.person.box.height);
    for (const Keypoint2D& k : f.person.keypoints) {
      if (!(k.confidence > 0) || !std::isfinite(k.x) || !std::isfinite(k.y)) continue;
      flow_from_.push_back({k.x, k.y});
      flow_limit_.push_back(limit);
    }
  }
  flow_to_.resize(flow_from_.size());
  flow_ok_.resize(flow_from_.size());
  flow_->track(flow_from_, flow_limit_, flow_to_, flow_ok_);
  std::size_t next = 0;  // the first point of the person in hand
  for (std::size_t i = 0; i < followed_.size(); ++i) {
    const Followed& f = followed_[i];
    if (!due_carry(f)) continue;
    // The points that flowed there and back; the person moves by their median motion.
    MovenetPerson person = f.person;
    const std::size_t first = next;
    flow_dx_.clear();
    flow_dy_.clear();
    for (const Keypoint2D& k : person.keypoints) {
      if (!(k.confidence > 0) || !std::isfinite(k.x) || !std::isfinite(k.y)) continue;
      const std::size_t p = next++;
      if (!flow_ok_[p]) continue;
      flow_dx_.push_back(flow_to_[p].x - flow_from_[p].x);
      flow_dy_.push_back(flow_to_[p].y - flow_from_[p].y);
    }
    if (static_cast<int>(flow_dx_.size()) < options_.min_keypoints) {
      ++profile_.flow_failed;
      continue;
    }
    const float dx = median(flow_dx_), dy = median(flow_dy_);
    // A keypoint whose own flow failed the check (hidden, blurred) follows the person, so the
    // skeleton and its box keep their shape until the next keypoint pass.
    std::size_t p = first;
    for (Keypoint2D& k : person.keypoints) {
      if (!(k.confidence > 0) || !std::isfinite(k.x) || !std::isfinite(k.y)) continue;
      k.x = flow_ok_[p] ? flow_to_[p].x : k.x + dx;
      k.y = flow_ok_[p] ? flow_to_[p].y : k.y + dy;
      ++p;
    }
    person.box = moved(person.box, dx, dy);
    out.push_back({person, moved(f.box, dx, dy), f.carried + 1, f.box_score, true, -1, f.id});
    carried_[i] = 1;
    ++profile_.carried;
  }
  profile_.flow += seconds_since(start);
}

void TopDownDetector::record_crops(const std::vector<Found>& found,
                                   const std::vector<DuplicateRule>& why) {
  using Fate = TopDownTrace::Fate;
  trace_.crops.assign(crop_boxes_.size(), {});
  for (std::size_t i = 0; i < crop_boxes_.size(); ++i)
    trace_.crops[i] = {
        crop_boxes_[i], newcomer_[i] != 0, {}, split_[i] ? Fate::split : Fate::rejected};
  for (std::size_t f = 0; f < found.size(); ++f) {
    if (found[f].crop < 0) continue;
    TopDownTrace::Crop& c = trace_.crops[static_cast<std::size_t>(found[f].crop)];
    c.found = found[f].person.box;
    c.fate = why[f] == DuplicateRule::none             ? Fate::kept
             : why[f] == DuplicateRule::box_overlap    ? Fate::duplicate_box
             : why[f] == DuplicateRule::same_keypoints ? Fate::duplicate_keypoints
                                                       : Fate::duplicate_similarity;
  }
}

void TopDownDetector::take_detections(const std::vector<Detection>& detections,
                                      std::size_t followed, const std::vector<Found>& found,
                                      std::vector<Box2D>& boxes) {
  if (options_.split_followed) {
    // A followed box over two detector boxes or more is that many people: their crop is set
    // aside (its box empty, overlapping nothing) and each box becomes a newcomer.
    for (std::size_t i = 0; i < followed; ++i) {
      const auto over = std::count_if(detections.begin(), detections.end(), [&](const auto& d) {
        return iou(boxes[i], d.box) > options_.followed_overlap;
      });
      if (over >= 2) split_[i] = 1;
    }
  }
  // A background run's boxes are of an earlier frame: they are compared with where the people
  // followed were then (who has moved since is still themselves).
  std::vector<Box2D> claimants;
  for (std::size_t i = 0; i < followed; ++i)
    claimants.push_back(split_[i] ? Box2D{} : at_detector_frame(box_ids_[i], boxes[i]));
  const std::vector<int> owner = followed_boxes(claimants, detections, options_.followed_overlap,
                                                options_.one_box_per_followed);
  // A followed person's detector score is the best of the boxes that are them (0: none): with
  // one_box_per_followed their own box's, else that of every box overlapping them.
  for (std::size_t i = 0; i < followed; ++i) {
    box_scores_[i] = 0;
    for (std::size_t d = 0; d < detections.size(); ++d)
      if (options_.one_box_per_followed
              ? owner[d] == static_cast<int>(i)
              : iou(claimants[i], detections[d].box) > options_.followed_overlap)
        box_scores_[i] = std::max(box_scores_[i], detections[d].score);
  }
  trace_.detections = detections;
  for (std::size_t d = 0; d < detections.size(); ++d) {
    const Box2D& box = detections[d].box;
    const bool carried = std::any_of(found.begin(), found.end(), [&](const Found& c) {
      return iou(at_detector_frame(c.id, c.person.box), box) > options_.followed_overlap;
    });
    trace_.taken_for.push_back(owner[d] >= 0 ? owner[d] : carried ? -2 : -1);
    if (owner[d] < 0 && !carried) {
      boxes.push_back(box);
      box_scores_.push_back(detections[d].score);
      box_ids_.push_back(-1);
      newcomer_.push_back(1);
      split_.push_back(0);
    }
  }
}

std::vector<TopDownDetector::Followed> TopDownDetector::follow(
    const std::vector<MovenetPerson>& people, const std::vector<Found>& found,
    const std::vector<std::size_t>& kept) {
  std::vector<Followed> next;
  for (std::size_t i = 0; i < people.size(); ++i) {
    const MovenetPerson& p = people[i];
    const Found& found_p = found[kept[i]];
    Followed f{found_p.follow, 0, 0, p, found_p.carried, found_p.box_score, found_p.id};
    const float cx = f.box.x + f.box.width / 2, cy = f.box.y + f.box.height / 2;
    float best = 0.3f;  // the predecessor must overlap the person this much
    for (const Followed& old : followed_) {
      const Box2D predicted = moved(old.box, old.vx, old.vy);
      const float overlap = iou(predicted, f.box);
      if (overlap <= best) continue;
      best = overlap;
      // Smoothed: half the new displacement, half the old motion.
      f.vx = 0.5f * (cx - (old.box.x + old.box.width / 2)) + 0.5f * old.vx;
      f.vy = 0.5f * (cy - (old.box.y + old.box.height / 2)) + 0.5f * old.vy;
    }
    if (f.id < 0) f.id = next_id_++;  // a newcomer's crop: somebody not followed as such
    next.push_back(f);
  }
  spread_keypoint_passes(next);
  return next;
}

void TopDownDetector::spread_keypoint_passes(std::vector<Followed>& next) const {
  const int every = options_.keypoint_every;
  if (every <= 1 || !options_.spread_keypoint_passes) return;
  // due[d]: the people whose next keypoint pass is d + 1 frames away (carried c: every - c).
  std::vector<int> due(static_cast<std::size_t>(every), 0);
  const auto slot = [every](int carried) {
    return static_cast<std::size_t>(every - 1 - std::min(carried, every - 1));
  };
  for (const Followed& f : next)
    if (f.carried > 0) ++due[slot(f.carried)];
  for (Followed& f : next) {
    if (f.carried != 0) continue;
    // A whole carry (the last slot) unless a sooner pass is due for fewer people.
    std::size_t best = due.size() - 1;
    for (std::size_t d = best; d-- > 0;)
      if (due[d] < due[best]) best = d;
    f.carried = every - 1 - static_cast<int>(best);
    ++due[best];
  }
}

std::vector<MovenetPerson> TopDownDetector::detect(const ImageBuffer& frame) {
  const auto start = Clock::now();
  if (flow_) {
    const auto flowing = Clock::now();
    flow_->next_frame(frame);
    profile_.flow += seconds_since(flowing);
  }
  // The people carried by optical flow; where each other followed person should be now.
  std::vector<Found> found;
  carry(found);
  std::vector<Box2D> boxes;
  box_scores_.clear();
  box_ids_.clear();
  newcomer_.clear();
  split_.clear();
  for (std::size_t i = 0; i < followed_.size(); ++i) {
    if (carried_[i]) continue;
    boxes.push_back(moved(followed_[i].box, followed_[i].vx, followed_[i].vy));
    box_scores_.push_back(followed_[i].box_score);
    box_ids_.push_back(followed_[i].id);
    newcomer_.push_back(0);
    split_.push_back(0);
  }
  // In the background, a frame with nobody followed has nothing else to do: it waits for the run
  // going on, or runs the person detector itself on its own picture.
  bool background = options_.detector_in_background;
  if (background && followed_.empty()) {
    if (background_->pending() > 0) {
      wait_for_detector();
    } else {
      background = false;
      detector_started_ = frame_;
    }
  }
  const bool rerun_allowed = frame_ - last_detector_frame_ >= options_.rerun_gap;
  const bool due =
      frame_ % options_.detect_every == 0 || (lost_someone_ && rerun_allowed) || followed_.empty();
  trace_.detections.clear();
  trace_.taken_for.clear();
  regions_.clear();
  crop_boxes_.clear();
  found_.clear();
  std::vector<Detection> detections;
  std::size_t cropped = 0;  // boxes whose keypoints are found
  const bool detector_ran = background ? finished_detector(detections) : due;
  if (detector_ran && !background) cropped = find_boxes_beside_crops(frame, boxes, detections);
  trace_.detector_ran = detector_ran;
  if (detector_ran) last_detector_frame_ = frame_;
  if (detector_ran) take_detections(detections, boxes.size(), found, boxes);
  add_crops(frame, std::span<const Box2D>(boxes).subspan(cropped), static_cast<int>(poses_.size()));
  people_found(frame, found);
  std::vector<MovenetPerson> people;
  std::vector<std::size_t> kept;  // per person: their index in `found`
  {
    // Of two finds of one person, the posed one wins (ranked first whatever its score).
    std::vector<MovenetPerson> candidates;
    for (const Found& f : found) {
      candidates.push_back(f.person);
      if (f.posed) candidates.back().score += 1;
    }
    std::vector<DuplicateRule> why;
    kept = distinct_people(
        candidates, DuplicateTest{options_.duplicate_overlap, 0.05f, options_.duplicate_similarity},
        &why);
    for (const std::size_t i : kept) people.push_back(found[i].person);
    record_crops(found, why);
  }
  std::vector<Followed> next = follow(people, found, kept);
  // A loss waits to be looked for: in the background until a run starts after it (the run going
  // on took its boxes before it), otherwise until the detector runs (rerun_gap frames after its
  // last run at the soonest).
  const bool lost_now = next.size() < followed_.size() && !detector_ran;
  lost_someone_ =
      background ? lost_someone_ || lost_now : (lost_someone_ || lost_now) && !detector_ran;
  followed_ = std::move(next);
  ++frame_;
  // In the background a run starts when none is going on, detect_every frames after the last
  // one started or after a frame that lost somebody (with nobody followed the next frame runs
  // the detector itself).
  if (options_.detector_in_background && background_->pending() == 0 && !followed_.empty() &&
      (frame_ - detector_started_ >= options_.detect_every || lost_someone_)) {
    start_detector(frame);
    lost_someone_ = false;
  }
  ++profile_.frames;
  profile_.crops += static_cast<long long>(boxes.size());
  profile_.total += seconds_since(start);
  return people;
}

}  // namespace mocap::detect
