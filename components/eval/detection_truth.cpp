#include "eval/detection_truth.hpp"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "core/input_error.hpp"
#include "io/read_file.hpp"

namespace mocap::eval {
namespace {

using nlohmann::json;

float overlap(const Box2D& a, const Box2D& b) {
  const float x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
  const float x1 = std::min(a.x + a.width, b.x + b.width);
  const float y1 = std::min(a.y + a.height, b.y + b.height);
  return std::max(0.0f, x1 - x0) * std::max(0.0f, y1 - y0);
}

float iou(const Box2D& a, const Box2D& b) {
  const float inter = overlap(a, b);
  const float uni = a.width * a.height + b.width * b.height - inter;
  return uni > 0 ? inter / uni : 0.0f;
}

std::vector<Box2D> read_boxes(const json& list, const std::string& where) {
  if (!list.is_array()) throw InputError(where, "expected a list of [x0, y0, x1, y1] boxes");
  std::vector<Box2D> boxes;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const json& b = list[i];
    const std::string at = where + "[" + std::to_string(i) + "]";
    if (!b.is_array() || b.size() != 4 || !std::all_of(b.begin(), b.end(), [](const json& v) {
          return v.is_number() && std::isfinite(v.get<double>()) &&
                 std::fabs(v.get<double>()) < 1e6;
        }))
      throw InputError(at, "expected [x0, y0, x1, y1], four finite numbers");
    const float x0 = b[0].get<float>(), y0 = b[1].get<float>();
    const float x1 = b[2].get<float>(), y1 = b[3].get<float>();
    if (!(x1 > x0 && y1 > y0)) throw InputError(at, "x1 must exceed x0 and y1 exceed y0");
    boxes.push_back({x0, y0, x1 - x0, y1 - y0});
  }
  return boxes;
}

}  // namespace

DetectionTruth parse_detection_truth(std::string_view text, const std::string& name) {
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded()) throw InputError(name, "not valid JSON");
  if (!j.is_object()) throw InputError(name, "expected a JSON object");
  DetectionTruth truth;
  const auto number = [&](const char* key, double lo, double hi) {
    const auto it = j.find(key);
    if (it == j.end() || !it->is_number() || !(it->get<double>() >= lo && it->get<double>() <= hi))
      throw InputError(name, std::string("key '") + key + "': expected a number in [" +
                                 std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return it->get<double>();
  };
  if (!j.contains("input") || !j["input"].is_string())
    throw InputError(name, "key 'input': expected the input's path");
  truth.input = j["input"].get<std::string>();
  truth.width = static_cast<int>(number("width", 1, 100000));
  truth.height = static_cast<int>(number("height", 1, 100000));
  truth.min_height = static_cast<float>(number("min_height", 0, 100000));
  if (!j.contains("frames") || !j["frames"].is_array())
    throw InputError(name, "key 'frames': expected a list");
  for (std::size_t i = 0; i < j["frames"].size(); ++i) {
    const json& f = j["frames"][i];
    const std::string where = name + ": frames[" + std::to_string(i) + "]";
    if (!f.is_object() || !f.contains("frame") || !f["frame"].is_number_integer() ||
        f["frame"].get<long long>() < 0 || f["frame"].get<long long>() > 10'000'000)
      throw InputError(where, "expected {\"frame\": N >= 0, \"people\": [...], \"ignore\": [...]}");
    TruthFrame frame;
    frame.frame = f["frame"].get<int>();
    if (!truth.frames.empty() && frame.frame <= truth.frames.back().frame)
      throw InputError(where, "frame numbers must ascend without repeats");
    frame.people = read_boxes(f.value("people", json::array()), where + ".people");
    frame.ignore = read_boxes(f.value("ignore", json::array()), where + ".ignore");
    truth.frames.push_back(std::move(frame));
  }
  return truth;
}

DetectionTruth read_detection_truth(const std::filesystem::path& file) {
  return parse_detection_truth(io::read_whole_file(file, 64u << 20), file.string());
}

FrameScore score_frame(const TruthFrame& truth, const std::vector<Box2D>& detections,
                       float min_iou) {
  FrameScore s;
  s.truths = static_cast<int>(truth.people.size());
  s.match.assign(detections.size(), -1);
  std::vector<bool> taken(truth.people.size(), false);
  for (std::size_t d = 0; d < detections.size(); ++d) {
    int best = -1;
    float best_iou = min_iou;
    for (std::size_t t = 0; t < truth.people.size(); ++t) {
      const float v = iou(detections[d], truth.people[t]);
      if (!taken[t] && v >= best_iou) best = static_cast<int>(t), best_iou = v;
    }
    if (best >= 0) {
      taken[static_cast<std::size_t>(best)] = true;
      s.match[d] = best;
      ++s.matched;
      continue;
    }
    const Box2D& b = detections[d];
    const bool ignored = std::any_of(truth.ignore.begin(), truth.ignore.end(), [&](const Box2D& g) {
      return iou(b, g) >= min_iou || overlap(b, g) > 0.5f * b.width * b.height;
    });
    if (ignored) s.match[d] = -2;
  }
  s.detections = static_cast<int>(
      std::count_if(s.match.begin(), s.match.end(), [](int m) { return m != -2; }));
  return s;
}

}  // namespace mocap::eval
