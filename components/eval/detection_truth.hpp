#pragma once
// Hand-checked person boxes for the detection evaluation (tests/data/detection/*.json, described
// in tests/data/detection/README.md), and the scores of a detector against them.
//
// File format (JSON):
//   {"input": "../shared/...", "width": W, "height": H, "min_height": 40,
//    "frames": [{"frame": 0, "people": [[x0, y0, x1, y1], ...], "ignore": [[x0, y0, x1, y1],
//    ...]}]}
// `people`: every person at least min_height pixels tall (their full extent, the hidden parts
// guessed); `ignore`: people who do not count either way (smaller, reflections, images of people):
// a detection on one is neither right nor wrong. Boxes in frame pixels.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/messages.hpp"

namespace mocap::eval {

struct TruthFrame {
  int frame = 0;
  std::vector<Box2D> people, ignore;
};

struct DetectionTruth {
  std::string input;
  int width = 0, height = 0;
  float min_height = 40;
  std::vector<TruthFrame> frames;  // ascending frame numbers, no repeats
};

// Throws InputError naming the file and the key for anything malformed.
DetectionTruth parse_detection_truth(std::string_view text, const std::string& name);
DetectionTruth read_detection_truth(const std::filesystem::path& file);

// The rule: a detection and a true box match when their IoU is at least `min_iou`; detections are
// matched greedily in the order given (best first), each true box at most once. Left-over
// detections overlapping an ignored box by `min_iou` (IoU) or lying mostly (> 50 % of their area)
// inside it are not counted.
struct FrameScore {
  int truths = 0, detections = 0, matched = 0;  // detections: the counted ones
  std::vector<int> match;  // per detection: index of its true box, −1 unmatched, −2 ignored
};
FrameScore score_frame(const TruthFrame& truth, const std::vector<Box2D>& detections,
                       float min_iou);

}  // namespace mocap::eval
