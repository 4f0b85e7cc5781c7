#include "detect/topdown_detector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "detect/image_tensor.hpp"
#include "detect/person_boxes.hpp"
#include "detect/person_proposals.hpp"

namespace mocap::detect {
namespace {

// How far above the eyes the head reaches, as a share of the keypoints' extent.
constexpr float kHeadMargin = 0.12f;

void check(const TopDownOptions& o) {
  if (o.detect_every < 1) throw std::invalid_argument("detect_every must be at least 1");
  if (!(o.crop_padding >= 1.0f && o.crop_padding <= 4.0f))
    throw std::invalid_argument("crop_padding must lie in [1, 4]");
  if (o.min_keypoints < 1 || o.min_keypoints > kMovenetKeypoints)
    throw std::invalid_argument("min_keypoints must lie in [1, 17]");
  if (o.detector_tiles < 1) throw std::invalid_argument("detector_tiles must be at least 1");
}

RunnerOptions runner_options(const TopDownOptions& o) {
  RunnerOptions r;
  r.backend = o.backend;
  r.threads = o.threads;
  return r;
}

Box2D moved(const Box2D& box, float dx, float dy) {
  return {box.x + dx, box.y + dy, box.width, box.height};
}

}  // namespace

TopDownDetector::TopDownDetector(const TopDownOptions& options,
                                 const std::filesystem::path& pose_model_json,
                                 const std::filesystem::path& centernet_json)
    : options_((check(options), options)),
      pose_(options.pose_model, pose_model_json, runner_options(options)),
      boxes_(std::make_unique<CenternetNetwork>(centernet_json, runner_options(options))) {}

TopDownDetector::~TopDownDetector() = default;

void TopDownDetector::reset() {
  followed_.clear();
  frame_ = 0;
  lost_someone_ = false;
}

std::vector<Detection> TopDownDetector::find_boxes(const ImageBuffer& frame) {
  ++detector_runs_;
  return propose_people(*boxes_, frame,
                        {options_.min_box_score, options_.box_overlap, options_.detector_tiles},
                        image_);
}

std::vector<MovenetPerson> TopDownDetector::pose(const ImageBuffer& frame,
                                                 const std::vector<Box2D>& boxes) {
  std::vector<MovenetPerson> people;
  if (boxes.empty()) return people;
  const int size = pose_.input_size();
  image_batch(crops_, static_cast<int>(boxes.size()), size, size);
  std::vector<SquareRegion> regions;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    regions.push_back(square_around(boxes[i], options_.crop_padding));
    fill_region(frame, regions.back(), crops_, static_cast<int>(i));
  }
  const std::vector<SinglePoseKeypoints> found = pose_.run(crops_);
  for (std::size_t i = 0; i < found.size(); ++i) {
    const SquareRegion& r = regions[i];
    MovenetPerson person;
    int passing = 0;
    float sum = 0;
    for (int k = 0; k < kMovenetKeypoints; ++k) {
      const auto& [y, x, score] = found[i][k];
      Keypoint2D& out = person.keypoints[k];
      if (score >= options_.min_keypoint_score) {
        out = {r.cx - r.side / 2 + x * r.side, r.cy - r.side / 2 + y * r.side, score};
        ++passing;
        sum += score;
      } else {
        out = {std::nanf(""), std::nanf(""), 0.0f};
      }
    }
    if (passing < options_.min_keypoints) continue;
    person.score = sum / static_cast<float>(passing);
    if (person.score < options_.min_person_score) continue;
    person.box = keypoint_box(person.keypoints, kHeadMargin);
    people.push_back(person);
  }
  return remove_duplicates(std::move(people), options_.duplicate_overlap);
}

std::vector<MovenetPerson> TopDownDetector::detect(const ImageBuffer& frame) {
  // Where each followed person should be now.
  std::vector<Box2D> boxes;
  for (const Followed& f : followed_) boxes.push_back(moved(f.box, f.vx, f.vy));
  const bool run_detector =
      frame_ % options_.detect_every == 0 || lost_someone_ || followed_.empty();
  if (run_detector) {
    for (const Detection& d : find_boxes(frame)) {
      const bool followed = std::any_of(boxes.begin(), boxes.end(), [&](const Box2D& b) {
        return iou(b, d.box) > options_.followed_overlap;
      });
      if (!followed) boxes.push_back(d.box);
    }
  }
  ++frame_;
  std::vector<MovenetPerson> people = pose(frame, boxes);

  // The next frame's crops: each person's box, moved by how far their nearest predecessor moved.
  std::vector<Followed> next;
  for (const MovenetPerson& p : people) {
    Followed f{p.box, 0, 0};
    const float cx = p.box.x + p.box.width / 2, cy = p.box.y + p.box.height / 2;
    float best = 0.3f;  // the predecessor must overlap the person this much
    for (const Followed& old : followed_) {
      const Box2D predicted = moved(old.box, old.vx, old.vy);
      const float overlap = iou(predicted, p.box);
      if (overlap <= best) continue;
      best = overlap;
      // Smoothed: half the new displacement, half the old motion.
      f.vx = 0.5f * (cx - (old.box.x + old.box.width / 2)) + 0.5f * old.vx;
      f.vy = 0.5f * (cy - (old.box.y + old.box.height / 2)) + 0.5f * old.vy;
    }
    next.push_back(f);
  }
  lost_someone_ = next.size() < followed_.size() && !run_detector;
  followed_ = std::move(next);
  return people;
}

}  // namespace mocap::detect
