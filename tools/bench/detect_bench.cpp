// mocap-bench-detect: the detection strategies side by side on real inputs (issue 18). Per input
// and strategy: recall and precision against the hand-checked boxes of tests/data/detection/,
// median keypoint distance to the reference strategy (the first listed), people per frame over
// every frame, and frames/s end to end (decoding + detection, offline, every frame in order, so
// that strategies that follow people between detector runs work as they would on the file). Each
// strategy runs on each network runtime asked for (--backends: cv::dnn, XNNPACK). Top-down
// strategies also get a table of where their time went (CenterNet, crops, keypoint passes). The
// networks' forward time alone is mocap-bench-networks'.
// Prints a Markdown table per input; --json writes every number.
//
// Also the tool that made the boxes: --candidates DIR writes the reference strategy's boxes on
// the frames to annotate in the truth format, --draw DIR the frames with the truth (green),
// ignored people (yellow) and the reference strategy's people (red, numbered) on a 50-px grid.

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_args.hpp"
#include "detect/image_tensor.hpp"
#include "detect/model_files.hpp"
#include "detect/movenet_detector.hpp"
#include "detect/person_boxes.hpp"
#include "detect/person_proposals.hpp"
#include "detect/tiled_detector.hpp"
#include "detect/topdown_detector.hpp"
#include "eval/detection_truth.hpp"
#include "video/video_source.hpp"

namespace {

using namespace mocap;
namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;
using People = std::vector<detect::MovenetPerson>;

// The grammar of a top-down strategy, for the errors and --help.
constexpr const char* kTopdownSpec =
    "topdown:MODEL:EVERY[:WORKERS[:THREADS]][:tTILES[w]][:sSCORE][:kEVERY][:eGAP][:uSURE][:"
    "bPRESENCE][:m0][:h1][:cH[xP]][:aIOU][:oOKS][:n1][:x1][:r1][:g1][:p0]";

struct Strategy {
  std::string name;
  std::function<People(const ImageBuffer&)> detect;
  std::function<void()> reset = [] {};
  // Top-down only: where its time went (zero elsewhere).
  std::function<detect::TopDownProfile()> profile = [] { return detect::TopDownProfile{}; };
  std::optional<detect::TopDownOptions> topdown;  // a top-down strategy's settings
  // Top-down only: what its last frame did with each box (for --diagnose).
  std::function<detect::TopDownTrace()> trace = [] { return detect::TopDownTrace{}; };
};

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, sep);)
    if (!item.empty()) out.push_back(item);
  return out;
}

// multipose:SIZE | tiles:CxR:TILE:FRAME | topdown:lightning|thunder:EVERY[:WORKERS[:THREADS]],
// on `backend`; a top-down spec's own THREADS replaces `threads`.
Strategy make_strategy(const std::string& spec, detect::Backend backend, int threads) {
  const auto parts = split(spec, ':');
  if (parts.size() == 2 && parts[0] == "multipose") {
    detect::MovenetOptions o;
    o.input_size = std::stoi(parts[1]);
    o.backend = backend;
    o.threads = threads;
    auto d = std::make_shared<detect::MovenetDetector>(detect::movenet_model_json(), o);
    return {spec, [d](const ImageBuffer& f) { return d->detect(f); }, [] {},
            [] { return detect::TopDownProfile{}; }, std::nullopt};
  }
  if (parts.size() == 4 && parts[0] == "tiles") {
    detect::TileOptions o;
    const auto grid = split(parts[1], 'x');
    if (grid.size() != 2) throw std::invalid_argument("tiles:CxR:TILE:FRAME, got " + spec);
    o.columns = std::stoi(grid[0]);
    o.rows = std::stoi(grid[1]);
    o.tile_input_size = std::stoi(parts[2]);
    o.frame_input_size = std::stoi(parts[3]);
    o.backend = backend;
    o.threads = threads;
    auto d = std::make_shared<detect::TiledDetector>(detect::movenet_model_json(), o);
    return {spec, [d](const ImageBuffer& f) { return d->detect(f); }, [] {},
            [] { return detect::TopDownProfile{}; }, std::nullopt};
  }
  if (parts.size() >= 3 && parts[0] == "topdown") {
    detect::TopDownOptions o;
    try {
      o.pose_model = detect::parse_pose_model(parts[1]);
    } catch (const std::invalid_argument&) {
      throw std::invalid_argument(std::string(kTopdownSpec) + " with MODEL " +
                                  std::string(detect::pose_model_names()) + ", got " + spec);
    }
    o.detect_every = std::stoi(parts[2]);
    // Then WORKERS and THREADS, and anywhere tN (person detector on N tiles; tNw: and the whole
    // frame), sX (its score threshold), kK (keypoint pass every K frames), uX (sure_box_score) and
    // bX (box_landmark_presence), m0 (the landmark box widened as the keypoints', not cut to the
    // picture: anatomical_landmark_box off), h1 (head_margin_from_shoulders), cH[xP] (boxes under
    // H px cropped with padding P: small_box_height, small_crop_padding), g1 (the person detector
    // in the background: detector_in_background; its runs end as the bench's pace allows), p0
    // (spread_keypoint_passes off).
    std::vector<std::string> numbers;
    for (std::size_t i = 3; i < parts.size(); ++i) {
      if (parts[i].size() > 1 && parts[i][0] == 't') {
        o.detector_tiles = std::stoi(parts[i].substr(1));
        o.detector_whole_frame = parts[i].back() == 'w';
      } else if (parts[i].size() > 1 && parts[i][0] == 'u')
        o.sure_box_score = std::stof(parts[i].substr(1));
      else if (parts[i].size() > 1 && parts[i][0] == 's')
        o.min_box_score = std::stof(parts[i].substr(1));
      else if (parts[i].size() > 1 && parts[i][0] == 'b')
        o.box_landmark_presence = std::stof(parts[i].substr(1));
      else if (parts[i] == "m0")
        o.anatomical_landmark_box = false;
      else if (parts[i].size() > 1 && parts[i][0] == 'a')
        o.newcomer_agreement = std::stof(parts[i].substr(1));
      else if (parts[i].size() > 1 && parts[i][0] == 'o')
        o.duplicate_similarity = std::stof(parts[i].substr(1));
      else if (parts[i] == "n1")
        o.one_box_per_followed = true;
      else if (parts[i] == "x1")
        o.split_followed = true;
      else if (parts[i] == "r1")
        o.detector_aspect = true;
      else if (parts[i] == "g1")
        o.detector_in_background = true;
      else if (parts[i] == "p0")
        o.spread_keypoint_passes = false;
      else if (parts[i] == "h1")
        o.head_margin_from_shoulders = true;
      else if (parts[i].size() > 1 && parts[i][0] == 'c') {
        // cH or cHxP: boxes under H px get crops of padding P (default small_crop_padding).
        const auto hp = split(parts[i].substr(1), 'x');
        o.small_box_height = std::stof(hp.at(0));
        if (hp.size() > 1) o.small_crop_padding = std::stof(hp[1]);
      } else if (parts[i].size() > 1 && parts[i][0] == 'k')
        o.keypoint_every = std::stoi(parts[i].substr(1));
      else if (parts[i].size() > 1 && parts[i][0] == 'e')
        o.rerun_gap = std::stoi(parts[i].substr(1));
      else
        numbers.push_back(parts[i]);
    }
    if (numbers.size() > 2)
      throw std::invalid_argument(std::string(kTopdownSpec) + ", got " + spec);
    o.backend = backend;
    o.threads = numbers.size() == 2 ? std::stoi(numbers[1]) : threads;
    o.workers = numbers.empty() ? 1 : std::stoi(numbers[0]);
    auto d = std::make_shared<detect::TopDownDetector>(
        o, detect::cached_model_json(detect::model_name(o.pose_model)),
        detect::cached_model_json("centernet"));
    d->warm_up();
    return {spec,
            [d](const ImageBuffer& f) { return d->detect(f); },
            [d] { d->reset(); },
            [d] { return d->profile(); },
            o,
            [d] { return d->trace(); }};
  }
  throw std::invalid_argument("unknown strategy '" + spec +
                              "' (multipose:SIZE, tiles:CxR:TILE:FRAME, " + kTopdownSpec + ")");
}

// Every frame of a video, or the one image of a still.
class Frames {
 public:
  explicit Frames(const std::string& path) : path_(path) {
    if (video::is_image_file_name(fs::path(path).filename().string())) {
      still_ = cv::imread(path);
      if (still_.empty()) throw std::runtime_error("cannot read " + path);
    } else {
      source_ = std::make_unique<video::VideoSource>(path);
    }
  }
  std::optional<ImageBuffer> next() {
    if (source_) {
      auto f = source_->read();
      if (!f) return std::nullopt;
      return f->image;
    }
    if (done_) return std::nullopt;
    done_ = true;
    auto owner = std::make_shared<cv::Mat>(still_);
    return ImageBuffer(still_.cols, still_.rows, static_cast<int>(still_.step[0]),
                       PixelFormat::bgr8, owner, reinterpret_cast<const std::byte*>(owner->data));
  }

 private:
  std::string path_;
  cv::Mat still_;
  bool done_ = false;
  std::unique_ptr<video::VideoSource> source_;
};

struct Run {
  std::map<int, People> people;  // every frame
  double seconds = 0;
  int frames = 0;
  std::vector<double> frame_ms;  // detect() per timed frame, wall clock
  int skipped = 0;  // --live-fps: frames a newer one replaced before the detector took them
  detect::TopDownProfile profile;              // of the timed frames (top-down only)
  std::map<int, detect::TopDownTrace> traces;  // top-down only: the frames in `keep_traces`
};

detect::TopDownProfile minus(detect::TopDownProfile a, const detect::TopDownProfile& b) {
  a.frames -= b.frames, a.detector_runs -= b.detector_runs, a.crops -= b.crops;
  a.total -= b.total, a.centernet -= b.centernet, a.crop_fill -= b.crop_fill;
  a.centernet_wait -= b.centernet_wait;
  a.keypoints -= b.keypoints;
  a.carried -= b.carried, a.flow_failed -= b.flow_failed, a.flow -= b.flow;
  return a;
}

// Every frame in order, or only those in `only` (sorted; empty: all); the top-down trace of the
// frames in `keep_traces` (sorted) is kept. With `live_fps` > 0 the frames come as from a camera
// at that rate: frame i exists from i / live_fps seconds on, the detector takes the newest frame
// when it is free and the frames it had no time for are skipped (a `latest` edge); a skipped
// frame's people are the last ones detected (what a live output shows at that moment).
Run run(Strategy& s, const std::string& input, const std::vector<int>& only,
        const std::vector<int>& keep_traces, double live_fps) {
  Run r;
  {
    // cv::dnn sets its layers up on the first forward pass (several times a later one): done
    // before the clock starts, on the first frame, and forgotten.
    Frames warm_up(input);
    if (auto f = warm_up.next()) s.detect(*f);
    s.reset();
  }
  Frames frames(input);
  const detect::TopDownProfile before = s.profile();
  const auto start = Clock::now();
  const auto captured = [&](int i) {
    return start + std::chrono::duration_cast<Clock::duration>(
                       std::chrono::duration<double>(i / std::max(live_fps, 1e-9)));
  };
  People last;
  for (int i = 0;; ++i) {
    auto f = frames.next();
    if (!f) break;
    if (!only.empty() && !std::binary_search(only.begin(), only.end(), i)) continue;
    if (live_fps > 0) {
      std::this_thread::sleep_until(captured(i));
      if (Clock::now() >= captured(i + 1)) {  // frame i + 1 is there: i was replaced
        r.people[i] = last;
        ++r.skipped;
        continue;
      }
    }
    const auto detecting = Clock::now();
    r.people[i] = last = s.detect(*f);
    r.frame_ms.push_back(1e3 * std::chrono::duration<double>(Clock::now() - detecting).count());
    if (s.topdown && std::binary_search(keep_traces.begin(), keep_traces.end(), i))
      r.traces[i] = s.trace();
    ++r.frames;
  }
  r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  r.profile = minus(s.profile(), before);
  return r;
}

bool present(const Keypoint2D& k) { return std::isfinite(k.x) && k.confidence > 0; }

std::vector<Box2D> boxes(const People& people) {
  std::vector<Box2D> out;
  for (const auto& p : people) out.push_back(p.box);
  return out;
}

// Distances of each person's keypoints to those of the reference person with the most
// overlapping box (IoU >= 0.5), over keypoints both have.
void keypoint_distances(const People& people, const People& reference, std::vector<double>& out) {
  for (const auto& p : people) {
    const detect::MovenetPerson* best = nullptr;
    float best_iou = 0.5f;
    for (const auto& r : reference) {
      const float v = detect::iou(p.box, r.box);
      if (v >= best_iou) best = &r, best_iou = v;
    }
    if (!best) continue;
    for (int k = 0; k < detect::kMovenetKeypoints; ++k)
      if (present(p.keypoints[k]) && present(best->keypoints[k]))
        out.push_back(std::hypot(p.keypoints[k].x - best->keypoints[k].x,
                                 p.keypoints[k].y - best->keypoints[k].y));
  }
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void draw(const std::string& input, const eval::DetectionTruth* truth, const std::vector<int>& at,
          const Run& reference, const fs::path& dir, const std::string& stem) {
  fs::create_directories(dir);
  Frames frames(input);
  for (int i = 0;; ++i) {
    auto f = frames.next();
    if (!f) break;
    if (!std::binary_search(at.begin(), at.end(), i)) continue;
    cv::Mat img = cv::Mat(f->height(), f->width(), CV_8UC3, const_cast<std::byte*>(f->data()),
                          static_cast<std::size_t>(f->stride()))
                      .clone();
    for (int x = 0; x < img.cols; x += 50)
      cv::line(img, {x, 0}, {x, img.rows},
               x % 100 ? cv::Scalar(90, 90, 90) : cv::Scalar(160, 160, 160));
    for (int y = 0; y < img.rows; y += 50)
      cv::line(img, {0, y}, {img.cols, y},
               y % 100 ? cv::Scalar(90, 90, 90) : cv::Scalar(160, 160, 160));
    for (int x = 0; x < img.cols; x += 100)
      cv::putText(img, std::to_string(x), {x + 2, 12}, cv::FONT_HERSHEY_PLAIN, 0.9,
                  {255, 255, 255});
    for (int y = 100; y < img.rows; y += 100)
      cv::putText(img, std::to_string(y), {2, y - 2}, cv::FONT_HERSHEY_PLAIN, 0.9, {255, 255, 255});
    const auto rect = [](const Box2D& b) {
      return cv::Rect(cv::Point(static_cast<int>(b.x), static_cast<int>(b.y)),
                      cv::Point(static_cast<int>(b.x + b.width), static_cast<int>(b.y + b.height)));
    };
    if (truth) {
      for (const auto& t : truth->frames) {
        if (t.frame != i) continue;
        for (const Box2D& b : t.people) cv::rectangle(img, rect(b), {0, 255, 0}, 2);
        for (const Box2D& b : t.ignore) cv::rectangle(img, rect(b), {0, 255, 255}, 1);
      }
    }
    const auto it = reference.people.find(i);
    if (it != reference.people.end()) {
      for (std::size_t n = 0; n < it->second.size(); ++n) {
        const Box2D& b = it->second[n].box;
        cv::rectangle(img, rect(b), {0, 0, 255}, 1);
        cv::putText(img, std::to_string(n), {static_cast<int>(b.x), static_cast<int>(b.y) - 2},
                    cv::FONT_HERSHEY_PLAIN, 1.0, {0, 0, 255});
      }
    }
    char name[64];
    std::snprintf(name, sizeof name, "_f%04d.png", i);
    cv::imwrite((dir / (stem + name)).string(), img);
  }
}

json candidates(const std::string& input, const Run& reference, const std::vector<int>& at,
                float min_height) {
  json frames = json::array();
  for (const int i : at) {
    json people = json::array(), ignore = json::array();
    const auto it = reference.people.find(i);
    if (it != reference.people.end()) {
      for (const auto& p : it->second) {
        const json box = {std::round(p.box.x), std::round(p.box.y),
                          std::round(p.box.x + p.box.width), std::round(p.box.y + p.box.height)};
        (p.box.height >= min_height ? people : ignore).push_back(box);
      }
    }
    frames.push_back({{"frame", i}, {"people", people}, {"ignore", ignore}});
  }
  return {{"input", input}, {"min_height", min_height}, {"frames", frames}};
}

// Which rule of the run lost a person whose proposal, cropped alone, shows them ((c3)), from the
// run's trace of the frame: the detector's box near them taken for a followed person, their crop
// dropped as a duplicate (by which rule), kept with a box elsewhere, or, between detector runs,
// no crop near them.
std::string dropped_by(const detect::TopDownTrace& t, const Box2D& truth) {
  using Fate = detect::TopDownTrace::Fate;
  const auto fate = [](Fate f) {
    switch (f) {
      case Fate::rejected:
        return "rejected";
      case Fate::kept:
        return "kept, box elsewhere (merged or a neighbour's)";
      case Fate::duplicate_box:
        return "dropped as duplicate: box IoU";
      case Fate::duplicate_keypoints:
        return "dropped as duplicate: same keypoints";
      case Fate::duplicate_similarity:
        return "dropped as duplicate: keypoint similarity";
      case Fate::split:
        return "set aside (split into the detector's boxes)";
    }
    return "?";
  };
  const auto nearest = [&](auto&& boxes, std::size_t n) {
    int best = -1;
    float best_iou = 0.3f;
    for (std::size_t i = 0; i < n; ++i)
      if (const float v = detect::iou(boxes(i), truth); v >= best_iou)
        best = static_cast<int>(i), best_iou = v;
    return best;
  };
  const auto crop_box = [&](std::size_t i) { return t.crops[i].box; };
  if (!t.detector_ran) {
    const int c = nearest(crop_box, t.crops.size());
    if (c < 0) return "(c3) not followed, no detector run on the frame";
    return std::string("(c3) no detector run, nearest crop ") +
           fate(t.crops[static_cast<std::size_t>(c)].fate);
  }
  const int d = nearest([&](std::size_t i) { return t.detections[i].box; }, t.detections.size());
  if (d < 0) return "(c3) detector ran, no box near them in the run";
  const int taken = t.taken_for[static_cast<std::size_t>(d)];
  if (taken == -2) return "(c3) their box taken for a person carried by flow";
  if (taken >= 0)
    return std::string("(c3) their box taken for a followed person (IoU > followed_overlap), ") +
           "whose crop was " + fate(t.crops[static_cast<std::size_t>(taken)].fate);
  for (const auto& c : t.crops)
    if (c.newcomer && detect::iou(c.box, t.detections[static_cast<std::size_t>(d)].box) > 0.99f)
      return std::string("(c3) their own crop ") + fate(c.fate);
  return "(c3) detector ran, their box not cropped";
}

// Why each true person a top-down strategy missed was missed (--diagnose): its person detector
// is run again on the annotated frames at the score floor `floor`, and each missed box is put in
// one cause: (d) a person was found near it but their box matches at IoU < min_iou (nearest
// IoU >= 0.3 among the found boxes matched to no other true person: a neighbour's box is not
// this person's loose box); (a) the detector proposed nothing near it (IoU >= 0.3) at any score >=
// floor; (b) only below the strategy's threshold; (c) proposed above it, yet no person came out
// near it (the keypoint stage rejected the crop, duplicate removal dropped it, or, between detector
// runs, no crop was looked at there). Prints a Markdown table per strategy.
void diagnose(const std::string& input, const eval::DetectionTruth& truth, const std::string& name,
              const Run& r, const detect::TopDownOptions& o, detect::Backend backend, int threads,
              float min_iou, float floor) {
  detect::RunnerOptions ro;
  ro.backend = backend;
  ro.threads = threads;
  // CenterNet as the strategy ran it: squeezed to 512 x 512, or at the frame's aspect.
  std::unique_ptr<detect::CenternetNetwork> network;
  const auto network_for = [&](const ImageBuffer& frame) -> detect::CenternetNetwork& {
    const auto [height, width] =
        o.detector_aspect && o.detector_tiles == 1
            ? detect::centernet_input_at_aspect(frame.width(), frame.height())
            : std::pair{detect::kCenternetInput, detect::kCenternetInput};
    if (!network || network->input_height() != height || network->input_width() != width)
      network = std::make_unique<detect::CenternetNetwork>(detect::cached_model_json("centernet"),
                                                           height, width, ro);
    return *network;
  };
  detect::SinglePoseNetwork pose(o.pose_model,
                                 detect::cached_model_json(detect::model_name(o.pose_model)), ro);
  const detect::ProposalOptions used{o.min_box_score, o.box_overlap, o.detector_tiles,
                                     o.detector_whole_frame};
  detect::GraphTensor scratch, crop;
  int alone_truths = 0, alone_counted = 0, alone_matched = 0;  // the proposals as the boxes
  detect::ProposalOptions low = used;
  low.min_score = floor;
  std::map<std::string, int> causes;
  // The same causes by true height (the brief's bands), with the found people as a first row.
  const std::array<const char*, 4> bands{"< 60 px", "60-100 px", "100-200 px", ">= 200 px"};
  std::map<std::string, std::array<int, 4>> by_cause;
  std::array<int, 4> band_people{};
  std::array<std::array<int, 4>, 3> false_finds{};  // loose, second box, nobody's; by height
  std::array<int, 5> rejected_score{};  // (c1): the crop's score in [0, 0.1), ..., [0.4, 0.5]+
  int band = 0;
  const auto count = [&](const std::string& cause) {
    causes[cause]++;
    by_cause[cause][static_cast<std::size_t>(band)]++;
  };
  std::map<std::string, std::pair<int, int>> by_height;  // found, all
  std::array<int, 3> nearest{};                          // misses by nearest IoU bucket
  std::array<int, 3> loose{};  // (d) by the nearest box's height: < 0.9, 0.9-1.1, > 1.1 x true
  int truths = 0;
  Frames frames(input);
  for (int i = 0;; ++i) {
    auto f = frames.next();
    if (!f) break;
    const auto t = std::find_if(truth.frames.begin(), truth.frames.end(),
                                [&](const eval::TruthFrame& tf) { return tf.frame == i; });
    if (t == truth.frames.end()) continue;
    const auto it = r.people.find(i);
    const std::vector<Box2D> found =
        it == r.people.end() ? std::vector<Box2D>{} : boxes(it->second);
    const auto score = eval::score_frame(*t, found, min_iou);
    const std::vector<detect::Detection> proposed =
        detect::propose_people(network_for(*f), *f, low, scratch);
    std::vector<Box2D> kept;
    for (const auto& d : proposed)
      if (d.score >= used.min_score) kept.push_back(d.box);
    const auto alone = eval::score_frame(*t, kept, min_iou);
    // Each false find: a loose box of a person nobody matched, a second box on a matched person,
    // or nobody's (no true box within IoU 0.3), by its own height.
    for (std::size_t d = 0; d < found.size(); ++d) {
      if (score.match[d] != -1) continue;
      float near = 0;
      int nearest_truth = -1;
      for (std::size_t k = 0; k < t->people.size(); ++k)
        if (const float v = detect::iou(found[d], t->people[k]); v > near)
          near = v, nearest_truth = static_cast<int>(k);
      const bool taken =
          std::find(score.match.begin(), score.match.end(), nearest_truth) != score.match.end();
      const int kind = near < 0.3f ? 2 : taken ? 1 : 0;
      const float h = found[d].height;
      false_finds[static_cast<std::size_t>(kind)][h < 60 ? 0 : h < 100 ? 1 : h < 200 ? 2 : 3]++;
    }
    alone_truths += alone.truths, alone_counted += alone.detections, alone_matched += alone.matched;
    for (std::size_t k = 0; k < t->people.size(); ++k) {
      const Box2D& box = t->people[k];
      ++truths;
      const bool hit = std::find(score.match.begin(), score.match.end(), static_cast<int>(k)) !=
                       score.match.end();
      const std::string band_name = box.height < 100   ? "< 100 px"
                                    : box.height < 150 ? "100-150 px"
                                    : box.height < 250 ? "150-250 px"
                                                       : ">= 250 px";
      by_height[band_name].second++;
      band = box.height < 60 ? 0 : box.height < 100 ? 1 : box.height < 200 ? 2 : 3;
      band_people[static_cast<std::size_t>(band)]++;
      if (hit) {
        by_height[band_name].first++;
        by_cause["found"][static_cast<std::size_t>(band)]++;
        continue;
      }
      // The nearest found box, and the nearest of those matched to no other true person: a
      // neighbour's box overlapping this one by 0.3-0.5 is not a loose box of this person.
      float near = 0, free_near = 0, near_height = 0;
      for (std::size_t j = 0; j < found.size(); ++j) {
        const float v = detect::iou(found[j], box);
        near = std::max(near, v);
        if (score.match[j] < 0 && v > free_near) free_near = v, near_height = found[j].height;
      }
      nearest[near < 0.1f ? 0 : near < 0.3f ? 1 : 2]++;
      float best_score = -1, best_iou = 0.3f;    // the best proposal near the box
      const detect::Detection* above = nullptr;  // the nearest passing the threshold
      for (const auto& d : proposed) {
        const float v = detect::iou(d.box, box);
        if (v < 0.3f) continue;
        best_score = std::max(best_score, d.score);
        if (d.score >= used.min_score && v >= best_iou) above = &d, best_iou = v;
      }
      if (free_near >= 0.3f) {
        count("(d) found, box IoU 0.3-0.5");
        const float ratio = near_height / box.height;
        loose[ratio < 0.9f ? 0 : ratio <= 1.1f ? 1 : 2]++;
      } else if (best_score < 0) {
        count("(a) no proposal near it");
      } else if (!above) {
        count("(b) proposal below threshold");
      } else {
        // The keypoint stage on that proposal's crop, as the strategy runs it.
        const detect::SquareRegion region = detect::crop_region(above->box, o);
        detect::image_batch(crop, 1, pose.input_size(), pose.input_size());
        detect::fill_region(*f, region, crop, 0);
        const detect::SinglePose answer = pose.run(crop).front();
        std::array<Keypoint2D, detect::kMovenetKeypoints> points{};
        for (int j = 0; j < detect::kMovenetKeypoints; ++j) {
          const auto& [y, x, c] = answer.keypoints[j];
          if (c < o.min_keypoint_score) continue;
          points[j] = {region.cx - region.side / 2 + x * region.side,
                       region.cy - region.side / 2 + y * region.side, c};
        }
        // A sure box is a person whatever its keypoints (TopDownOptions::sure_box_score).
        const bool sure = o.sure_box_score > 0 && above->score >= o.sure_box_score;
        const detect::CropVerdict verdict = detect::judge_crop(answer, o);
        // A newcomer whose posed box disagrees with its proposal is rejected too (agreement).
        const bool agrees =
            o.newcomer_agreement <= 0 ||
            detect::iou(detect::posed_box(answer, region, o, f->width(), f->height()),
                        above->box) >= o.newcomer_agreement;
        const bool posed = verdict.posed && agrees;
        if (!posed && !sure) {
          count("(c1) proposed, crop's keypoints rejected");
          rejected_score[static_cast<std::size_t>(
              std::clamp(static_cast<int>(verdict.score * 10), 0, 4))]++;
        } else if (posed && detect::iou(detect::keypoint_box(points, 0.12f), box) < 0.3f) {
          count("(c2) proposed, crop's keypoints on someone else");
        } else {
          const auto trace = r.traces.find(i);
          count(trace == r.traces.end() ? "(c3) proposed, no trace of the frame"
                                        : dropped_by(trace->second, box));
        }
      }
    }
  }
  std::printf("\n#### %s: why true people were missed (proposals at score >= %.2f, %d tile%s)\n\n",
              name.c_str(), floor, used.tiles, used.tiles == 1 ? "" : "s");
  std::printf("| cause | people | share of the %d true people |\n|---|---|---|\n", truths);
  for (const auto& [cause, n] : causes)
    std::printf("| %s | %d | %.3f |\n", cause.c_str(), n, static_cast<double>(n) / truths);
  std::printf("\nThe proposals alone (score >= %.2f) as the boxes: recall %.3f, precision %.3f\n",
              used.min_score, static_cast<double>(alone_matched) / std::max(1, alone_truths),
              static_cast<double>(alone_matched) / std::max(1, alone_counted));
  std::printf(
      "\nMisses by the IoU of the nearest found person: < 0.1: %d, 0.1-0.3: %d, "
      "0.3-0.5: %d (its box's height < 0.9 x the true one: %d, 0.9-1.1: %d, > 1.1: %d)\n\n"
      "| true height | recall |\n|---|---|\n",
      nearest[0], nearest[1], nearest[2], loose[0], loose[1], loose[2]);
  for (const auto& [band_name, n] : by_height)
    std::printf("| %s | %d / %d |\n", band_name.c_str(), n.first, n.second);
  std::printf("\n| cause, by true height | %s | %s | %s | %s |\n|---|---|---|---|---|\n", bands[0],
              bands[1], bands[2], bands[3]);
  for (const auto& [cause, n] : by_cause)
    std::printf("| %s | %d | %d | %d | %d |\n", cause.c_str(), n[0], n[1], n[2], n[3]);
  std::printf("| true people | %d | %d | %d | %d |\n", band_people[0], band_people[1],
              band_people[2], band_people[3]);
  const std::array<const char*, 3> false_kinds{
      "false find: loose box (IoU 0.3-0.5) of an unmatched person",
      "false find: second box on a matched person (IoU >= 0.3)",
      "false find: nobody's (no true box at IoU >= 0.3)"};
  std::printf("\n| false finds, by their own height | %s | %s | %s | %s |\n|---|---|---|---|---|\n",
              bands[0], bands[1], bands[2], bands[3]);
  for (std::size_t k = 0; k < false_kinds.size(); ++k)
    std::printf("| %s | %d | %d | %d | %d |\n", false_kinds[k], false_finds[k][0],
                false_finds[k][1], false_finds[k][2], false_finds[k][3]);
  std::printf(
      "\n(c1) by the rejected crop's score (BlazePose: its pose flag; MoveNet: the passing "
      "keypoints' mean): [0, 0.1) %d, [0.1, 0.2) %d, [0.2, 0.3) %d, [0.3, 0.4) %d, >= 0.4 %d\n",
      rejected_score[0], rejected_score[1], rejected_score[2], rejected_score[3],
      rejected_score[4]);
  std::fflush(stdout);
}

// Where the top-down strategies' time went, in ms per frame.
void print_profiles(const std::vector<std::string>& names, const std::vector<Run>& runs) {
  bool header = false;
  for (std::size_t s = 0; s < runs.size(); ++s) {
    const detect::TopDownProfile& p = runs[s].profile;
    if (p.frames == 0) continue;
    if (!header)
      std::printf(
          "\n| top-down strategy | crops/frame | detector runs | ms/frame: detect() (p50 / p95 / "
          "max) | "
          "CenterNet (per run; on the caller) | crop cutting | keypoint passes (per crop) | "
          "optical flow | rest | carried by flow /frame (flow failed) |\n"
          "|---|---|---|---|---|---|---|---|---|---|\n");
    header = true;
    const double f = static_cast<double>(p.frames);
    const double rest = p.total - p.centernet_wait - p.crop_fill - p.keypoints - p.flow;
    std::vector<double> ms = runs[s].frame_ms;
    std::sort(ms.begin(), ms.end());
    const auto at = [&ms](double q) {
      return ms.empty() ? 0.0
                        : ms[static_cast<std::size_t>(q * static_cast<double>(ms.size() - 1))];
    };
    std::printf(
        "| %s | %.2f | %lld | %.1f (%.1f / %.1f / %.1f) | %.1f (%.1f; %.1f waited) | %.1f | %.1f "
        "(%.2f) | %.1f | %.1f | %.2f (%lld) |\n",
        names[s].c_str(), static_cast<double>(p.crops) / f, p.detector_runs, 1e3 * p.total / f,
        at(0.5), at(0.95), at(1.0), 1e3 * p.centernet / f,
        p.detector_runs ? 1e3 * p.centernet / static_cast<double>(p.detector_runs) : 0.0,
        1e3 * p.centernet_wait / f, 1e3 * p.crop_fill / f, 1e3 * p.keypoints / f,
        p.crops ? 1e3 * p.keypoints / static_cast<double>(p.crops) : 0.0, 1e3 * p.flow / f,
        1e3 * rest / f, static_cast<double>(p.carried) / f, p.flow_failed);
  }
}

}  // namespace

int main(int argc, char** argv) {
  cli::Args args("mocap-bench-detect [options]",
                 "Detection strategies side by side: recall, precision, keypoint distance, "
                 "people per frame, frames/s, one Markdown table per input");
  args.option("inputs", "LIST",
              "videos or stills, comma-separated; the truth of each is TRUTH/<stem>.json",
              "../shared/data/eval/openpose_examples_media/video.avi,"
              "/usr/share/doc/opencv-doc/examples/data/vtest.avi,"
              "../shared/data/eval/opencv_samples/vtest_part0.avi,"
              "../shared/data/eval/openpose_examples_media/COCO_val2014_000000000241.jpg,"
              "../shared/data/eval/openpose_examples_media/COCO_val2014_000000000328.jpg,"
              "../shared/data/eval/openpose_examples_media/COCO_val2014_000000000536.jpg")
      .option("strategies", "LIST",
              "the first (on the first runtime) is the reference for keypoint distances: "
              "multipose:SIZE, "
              "tiles:CxR:TILE:FRAME, " +
                  std::string(kTopdownSpec) +
                  " (MODEL: lightning, thunder, blazepose-lite, blazepose-full, blazepose-heavy; "
                  "workers: copies of the keypoint network sharing a frame's crops; tTILES: "
                  "person detector tiles, tTILESw: and the whole frame, sSCORE: its box score "
                  "floor, uSURE: boxes scoring SURE are people whatever their keypoints, "
                  "bPRESENCE: BlazePose boxes from the landmarks of this presence (default 0.5; "
                  "above 1: from the kept keypoints), m0: that landmark box widened as the "
                  "keypoints' and not cut to the picture (before the anatomical margins), h1: "
                  "BlazePose's head margin at least 0.54 x the eyes' height above the shoulders, "
                  "cH[xP]: boxes under H px get crops of padding P (default 1.5), aIOU: a "
                  "newcomer is a person only when its posed box overlaps the detector's by this "
                  "IoU, oOKS: finds sharing 3 keypoints are one person only at this keypoint "
                  "similarity (COCO OKS; 0.9: HRNet's), n1: a followed person is at most one "
                  "detector box (others overlapping them get crops), x1: a followed box over 2+ "
                  "detector boxes is split into them, r1: CenterNet sees the frame at its aspect "
                  "(512 x 896 for 16:9) instead of squeezed to 512 x 512, eGAP: a detector "
                  "re-run after a loss only GAP frames after its last run, kEVERY: keypoint pass "
                  "every EVERY frames, optical flow between, g1: the person detector in the "
                  "background (no frame waits for it; live), p0: keypoint passes not spread over "
                  "the frames between; a top-down strategy also prints where its time went)",
              "topdown:thunder:1,multipose:256,multipose:512,tiles:2x2:256:256,"
              "topdown:lightning:1,topdown:lightning:10,topdown:thunder:10")
      .option("truth", "DIR", "hand-checked boxes", "tests/data/detection")
      .option("iou", "X", "a detection matches a true box at this IoU", "0.5")
      .option("backends", "LIST",
              "network runtimes, each strategy runs on each: auto, xnnpack, opencv", "auto")
      .option("threads", "N", "network threads (0: XNNPACK 1, cv::dnn OpenCV's default)", "0")
      .option("json", "FILE", "write every number here")
      .option("live-fps", "F",
              "frames come as from a camera at F frames/s: the detector takes the newest when "
              "free, the others are skipped and show the last people found (live recall)")
      .flag("only-annotated",
            "detect on the annotated frames only (each one alone: no following between frames; "
            "quick, for making candidates)")
      .option("diagnose", "FLOOR",
              "for each top-down strategy, why each missed true person was missed: its person "
              "detector again at this score floor (e.g. 0.05)")
      .option("draw", "DIR", "draw the annotated frames with the truth and the reference's people")
      .option("candidates", "DIR",
              "write the reference's boxes on the frames to annotate (30 spread over a video when "
              "it has no truth yet) as <stem>.json");
  int exit_code = 0;
  if (!args.parse(argc - 1, argv + 1, exit_code)) return exit_code;
  try {
    const float min_iou = std::stof(args.get("iou"));
    const double live_fps = args.has("live-fps") ? std::stod(args.get("live-fps")) : 0.0;
    const int threads = static_cast<int>(args.integer("threads"));
    json report = {{"iou", min_iou}, {"inputs", json::array()}};
    for (const std::string& input : split(args.get("inputs"), ',')) {
      const std::string stem = fs::path(input).stem().string();
      const fs::path truth_file = fs::path(args.get("truth")) / (stem + ".json");
      std::optional<eval::DetectionTruth> truth;
      if (fs::exists(truth_file)) truth = eval::read_detection_truth(truth_file);
      std::vector<int> at;
      if (truth) {
        for (const auto& f : truth->frames) at.push_back(f.frame);
      } else {
        const int n =
            static_cast<int>(video::is_image_file_name(fs::path(input).filename().string())
                                 ? 1
                                 : video::VideoSource(input).frame_count());
        const int count = std::min(30, n);
        for (int k = 0; k < count; ++k) at.push_back(k * n / count);
      }
      const std::vector<int> only = args.has("only-annotated") ? at : std::vector<int>{};
      std::vector<Run> runs;
      std::vector<std::string> names;
      std::vector<std::optional<detect::TopDownOptions>> topdowns;
      std::vector<detect::Backend> backends;
      for (const std::string& spec : split(args.get("strategies"), ',')) {
        for (const std::string& runtime : split(args.get("backends"), ',')) {
          const detect::Backend backend = detect::resolve_backend(detect::parse_backend(runtime));
          Strategy s = make_strategy(spec, backend, threads);
          runs.push_back(run(s, input, only, at, live_fps));
          topdowns.push_back(s.topdown);
          backends.push_back(backend);
          names.push_back(spec + "@" + std::string(detect::backend_name(backend)));
          std::fprintf(stderr, "%s %s: %d frames, %.1f s\n", stem.c_str(), names.back().c_str(),
                       runs.back().frames, runs.back().seconds);
        }
      }
      if (args.has("candidates")) {
        fs::create_directories(args.get("candidates"));
        std::ofstream(fs::path(args.get("candidates")) / (stem + ".json"))
            << candidates(input, runs.front(), at, truth ? truth->min_height : 40.0f).dump(1)
            << "\n";
      }
      if (args.has("draw"))
        draw(input, truth ? &*truth : nullptr, at, runs.front(), args.get("draw"), stem);

      json rows = json::array();
      std::printf("\n### %s (%d frames%s)\n\n", input.c_str(), runs.front().frames,
                  truth ? (", " + std::to_string(truth->frames.size()) + " annotated").c_str()
                        : ", no truth");
      std::printf(
          "| strategy | recall | precision | true people | median kp dist to %s (px) | "
          "people/frame | frames/s |\n|---|---|---|---|---|---|---|\n",
          names.front().c_str());
      for (std::size_t s = 0; s < runs.size(); ++s) {
        int truths = 0, counted = 0, matched = 0;
        if (truth) {
          for (const auto& f : truth->frames) {
            const auto it = runs[s].people.find(f.frame);
            const auto score = eval::score_frame(
                f, it == runs[s].people.end() ? std::vector<Box2D>{} : boxes(it->second), min_iou);
            truths += score.truths, counted += score.detections, matched += score.matched;
          }
        }
        std::vector<double> distances;
        std::size_t people = 0;
        for (const auto& [frame, found] : runs[s].people) {
          people += found.size();
          const auto ref = runs.front().people.find(frame);
          if (ref != runs.front().people.end()) keypoint_distances(found, ref->second, distances);
        }
        const double recall = truths ? static_cast<double>(matched) / truths : std::nan("");
        const double precision = counted ? static_cast<double>(matched) / counted : std::nan("");
        // Per frame of the video (with --live-fps a skipped frame shows the last people found).
        const double per_frame =
            static_cast<double>(people) /
            static_cast<double>(std::max<std::size_t>(1, runs[s].people.size()));
        const double fps = runs[s].frames / std::max(1e-9, runs[s].seconds);
        const double dist = median(distances);
        std::printf("| %s | %.3f | %.3f | %d | %.1f | %.2f | %.1f |\n", names[s].c_str(), recall,
                    precision, truths, dist, per_frame, fps);
        rows.push_back({{"strategy", names[s]},
                        {"recall", recall},
                        {"precision", precision},
                        {"true_people", truths},
                        {"matched", matched},
                        {"counted_detections", counted},
                        {"median_keypoint_distance_px", dist},
                        {"people_per_frame", per_frame},
                        {"frames_per_second", fps},
                        {"frames", runs[s].frames},
                        {"skipped_live", runs[s].skipped},
                        {"seconds", runs[s].seconds}});
      }
      // No cap on people (issue 18): how many frames show more than MultiPose's 6.
      for (std::size_t s = 0; s < runs.size(); ++s) {
        int crowded = 0;
        std::size_t most = 0;
        for (const auto& [frame, found] : runs[s].people) {
          crowded += found.size() > 6 ? 1 : 0;
          most = std::max(most, found.size());
        }
        std::printf("%s%s: %d of %d frames with more than 6 people found (at most %zu)%s\n",
                    s == 0 ? "\n" : "", names[s].c_str(), crowded, runs[s].frames, most,
                    live_fps > 0
                        ? ("; " + std::to_string(runs[s].skipped) + " frames skipped live").c_str()
                        : "");
      }
      print_profiles(names, runs);
      std::fflush(stdout);
      if (args.has("diagnose") && truth)
        for (std::size_t s = 0; s < runs.size(); ++s)
          if (topdowns[s])
            diagnose(input, *truth, names[s], runs[s], *topdowns[s], backends[s], threads, min_iou,
                     std::stof(args.get("diagnose")));
      report["inputs"].push_back({{"input", input}, {"rows", rows}});
    }
    if (args.has("json")) std::ofstream(args.get("json")) << report.dump(1) << "\n";
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-detect: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
