#include "io/openpose_json.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <system_error>

#include <nlohmann/json.hpp>

#include "core/input_error.hpp"
#include "io/read_file.hpp"

namespace mocap::io {
namespace {

using nlohmann::json;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// One parsed file before the folder decides the layout: `keypoints` is 0 when nobody is in it.
struct ParsedFrame {
  People2D people;
  int keypoints = 0;
};

std::optional<LayoutId> layout_for_count(int keypoints) {
  switch (keypoints) {
    case 25:
      return LayoutId::body25;  // or BODY_25B: decided by the options
    case 18:
      return LayoutId::coco18;
    case 17:
      return LayoutId::coco17;
    default:
      return std::nullopt;
  }
}

std::string person_key(std::size_t person) { return "people[" + std::to_string(person) + "]"; }

int read_person_id(const json& person) {
  const auto it = person.find("person_id");
  if (it == person.end()) return -1;
  if (it->is_number_integer()) return it->get<int>();
  if (it->is_array() && it->size() == 1 && (*it)[0].is_number_integer()) return (*it)[0].get<int>();
  return -1;  // OpenPose writes [-1]; anything else carries no usable id
}

Box2D box_of(const std::vector<Keypoint2D>& joints) {
  float x0 = std::numeric_limits<float>::max(), y0 = x0;
  float x1 = std::numeric_limits<float>::lowest(), y1 = x1;
  bool any = false;
  for (const auto& k : joints) {
    if (!(k.confidence > 0.0f)) continue;
    any = true;
    x0 = std::min(x0, k.x), y0 = std::min(y0, k.y);
    x1 = std::max(x1, k.x), y1 = std::max(y1, k.y);
  }
  if (!any) return {};
  return {x0, y0, x1 - x0, y1 - y0};
}

// Reads people[i].pose_keypoints_2d; an empty array (a person OpenPose found only a face or
// hands for) gives nullopt.
std::optional<Person2D> read_person(const json& person, std::size_t index,
                                    const std::string& source) {
  const std::string key = person_key(index);
  if (!person.is_object()) throw InputError(source, key + " is not an object");
  const auto it = person.find("pose_keypoints_2d");
  if (it == person.end() || !it->is_array()) {
    throw InputError(source, key + ".pose_keypoints_2d is missing or not an array");
  }
  const json& values = *it;
  if (values.empty()) return std::nullopt;
  if (values.size() % 3 != 0) {
    throw InputError(source, key + ".pose_keypoints_2d holds " + std::to_string(values.size()) +
                                 " values, not a multiple of 3 (x, y, confidence)");
  }
  const int count = static_cast<int>(values.size() / 3);
  if (!layout_for_count(count)) {
    throw InputError(source, key + ".pose_keypoints_2d has " + std::to_string(count) +
                                 " keypoints; expected 25 (BODY_25, BODY_25B), 18 (COCO-18) or "
                                 "17 (COCO-17)");
  }
  Person2D out;
  out.id = read_person_id(person);
  out.joints.resize(count);
  float xyc[3];
  for (int k = 0; k < count; ++k) {
    for (int c = 0; c < 3; ++c) {
      const json& v = values[3 * k + c];
      const double value = v.is_number() ? v.get<double>() : kNaN;
      if (!std::isfinite(value)) {
        throw InputError(source, key + ".pose_keypoints_2d[" + std::to_string(3 * k + c) +
                                     "] is not a finite number: " + v.dump());
      }
      xyc[c] = static_cast<float>(value);
    }
    out.joints[k] = xyc[2] > 0.0f ? Keypoint2D{xyc[0], xyc[1], xyc[2]} : Keypoint2D{kNaN, kNaN, 0};
  }
  out.box = box_of(out.joints);
  return out;
}

json parse_document(std::string_view text, const std::string& source) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) {
    throw InputError(source, "empty file (expected OpenPose JSON)");
  }
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    // Syntax errors name line and column ("parse error at line 1, column 812: ..."); numbers
    // too large for a double ("1e999") are out_of_range errors.
    throw InputError(source, std::string("not valid JSON: ") + e.what());
  }
}

ParsedFrame parse_frame(std::string_view text, const std::string& source) {
  const json doc = parse_document(text, source);
  if (!doc.is_object()) throw InputError(source, "top level is not a JSON object");
  const auto people = doc.find("people");
  if (people == doc.end() || !people->is_array()) {
    throw InputError(source, "no \"people\" array (is this OpenPose --write_json output?)");
  }
  ParsedFrame out;
  out.people.header.stream = source;
  for (std::size_t i = 0; i < people->size(); ++i) {
    auto person = read_person((*people)[i], i, source);
    if (!person) continue;
    const int count = static_cast<int>(person->joints.size());
    if (out.keypoints != 0 && count != out.keypoints) {
      throw InputError(source, person_key(i) + " has " + std::to_string(count) +
                                   " keypoints but earlier people have " +
                                   std::to_string(out.keypoints));
    }
    out.keypoints = count;
    out.people.people.push_back(std::move(*person));
  }
  return out;
}

LayoutId resolve_layout(int keypoints, Body25Choice choice, const Body25Votes& votes) {
  const LayoutId by_count = layout_for_count(keypoints).value_or(LayoutId::body25);
  if (by_count != LayoutId::body25) return by_count;
  switch (choice) {
    case Body25Choice::body25:
      return LayoutId::body25;
    case Body25Choice::body25b:
      return LayoutId::body25b;
    case Body25Choice::detect:
      return votes.decision();
  }
  return LayoutId::body25;
}

bool detected(const Keypoint2D& k) { return k.confidence > 0.0f; }

float distance(const Keypoint2D& a, const Keypoint2D& b) {
  return std::hypot(a.x - b.x, a.y - b.y);
}

// +1 BODY_25B, -1 BODY_25, 0 abstain; see Body25Votes.
int vote_of(const Person2D& person) {
  const auto& k = person.joints;
  if (k.size() != 25 || !detected(k[0])) return 0;
  float nearest = std::numeric_limits<float>::max();
  for (int i : {15, 16}) {
    if (detected(k[i])) nearest = std::min(nearest, distance(k[0], k[i]));
  }
  if (nearest == std::numeric_limits<float>::max()) return 0;
  float extent = 0.0f;
  int count = 0;
  for (const auto& p : k) {
    if (!detected(p)) continue;
    ++count;
    extent = std::max(extent, distance(k[0], p));
  }
  if (!(extent > 0.0f)) return 0;
  const float r = nearest / extent;
  if (r > 0.6f) return +1;
  if (r < 0.25f && count >= 8) return -1;
  return 0;
}

}  // namespace

void Body25Votes::add(const Body25Votes& other) {
  body25 += other.body25;
  body25b += other.body25b;
  abstained += other.abstained;
}

Body25Votes vote_body25_variant(const People2D& frame) {
  Body25Votes votes;
  for (const auto& person : frame.people) {
    const int v = vote_of(person);
    (v > 0 ? votes.body25b : v < 0 ? votes.body25 : votes.abstained) += 1;
  }
  return votes;
}

People2D parse_openpose_json(std::string_view text, const std::string& source,
                             const OpenPoseOptions& options) {
  ParsedFrame parsed = parse_frame(text, source);
  parsed.people.layout =
      resolve_layout(parsed.keypoints, options.body25, vote_body25_variant(parsed.people));
  return std::move(parsed.people);
}

People2D read_openpose_file(const std::filesystem::path& file, const OpenPoseOptions& options) {
  return parse_openpose_json(read_whole_file(file, options.max_file_bytes), file.string(), options);
}

std::optional<std::int64_t> frame_number(std::string_view name) {
  const auto dot = name.rfind('.');
  if (dot != std::string_view::npos) name = name.substr(0, dot);
  std::size_t end = name.size();
  while (end > 0 && !std::isdigit(static_cast<unsigned char>(name[end - 1]))) --end;
  if (end == 0) return std::nullopt;
  std::size_t begin = end;
  while (begin > 0 && std::isdigit(static_cast<unsigned char>(name[begin - 1]))) --begin;
  // More than 18 digits would overflow; such a name is not a frame file.
  if (end - begin > 18) return std::nullopt;
  std::int64_t n = 0;
  for (std::size_t i = begin; i < end; ++i) n = n * 10 + (name[i] - '0');
  return n;
}

std::vector<FrameFile> list_frame_files(const std::filesystem::path& folder) {
  std::error_code ec;
  std::filesystem::directory_iterator it(folder, ec);
  if (ec) throw InputError(folder.string(), "cannot list folder: " + ec.message());
  std::vector<FrameFile> files;
  for (; it != std::filesystem::directory_iterator(); it.increment(ec)) {
    if (ec) throw InputError(folder.string(), "cannot list folder: " + ec.message());
    const auto& path = it->path();
    if (path.extension() != ".json" || it->is_directory(ec)) continue;
    if (const auto n = frame_number(path.filename().string())) files.push_back({path, *n});
  }
  std::sort(files.begin(), files.end(), [](const FrameFile& a, const FrameFile& b) {
    return a.number != b.number ? a.number < b.number : a.path.filename() < b.path.filename();
  });
  return files;
}

std::string_view to_string(FrameProblemKind kind) {
  switch (kind) {
    case FrameProblemKind::missing:
      return "missing";
    case FrameProblemKind::malformed:
      return "malformed";
    case FrameProblemKind::duplicate:
      return "duplicate";
    case FrameProblemKind::layout_mismatch:
      return "layout mismatch";
  }
  return "?";
}

namespace {

// The reading state of read_openpose_folder: one slot per frame number.
class FolderReader {
 public:
  FolderReader(const OpenPoseOptions& options, std::int64_t first_frame, std::size_t slots)
      : options_(options), keypoints_(slots, 0), files_(slots) {
    out_.first_frame = first_frame;
    out_.frames.resize(slots);
  }

  OpenPoseSequence read(const std::vector<FrameFile>& files, const std::string& stream) {
    for (const auto& f : files) read_file(f);
    report_gaps();
    settle_layout();
    std::stable_sort(
        out_.problems.begin(), out_.problems.end(),
        [](const FrameProblem& a, const FrameProblem& b) { return a.frame < b.frame; });
    stamp_headers(stream);
    return std::move(out_);
  }

 private:
  std::int64_t frame_of(std::size_t slot) const {
    return out_.first_frame + static_cast<std::int64_t>(slot);
  }

  void problem(FrameProblemKind kind, std::int64_t frame, std::int64_t count,
               const std::string& file, const std::string& message) {
    out_.problems.push_back({kind, frame, count, file, message});
  }

  void read_file(const FrameFile& f) {
    const std::size_t slot = static_cast<std::size_t>(f.number - out_.first_frame);
    const std::string name = f.path.string();
    if (!files_[slot].empty()) {
      problem(FrameProblemKind::duplicate, f.number, 1, name,
              name + ": frame " + std::to_string(f.number) + " was already read from " +
                  files_[slot] + "; this file is ignored");
      return;
    }
    files_[slot] = name;
    try {
      ParsedFrame parsed = parse_frame(read_whole_file(f.path, options_.max_file_bytes), name);
      out_.frames[slot] = std::move(parsed.people);
      keypoints_[slot] = parsed.keypoints;
    } catch (const InputError& e) {
      problem(FrameProblemKind::malformed, f.number, 1, name,
              std::string(e.what()) + ": left empty");
    }
  }

  // One problem per run of missing numbers, so that a wild gap costs one line, not millions.
  void report_gaps() {
    for (std::size_t slot = 0; slot < files_.size();) {
      if (!files_[slot].empty()) {
        ++slot;
        continue;
      }
      std::size_t end = slot;
      while (end < files_.size() && files_[end].empty()) ++end;
      const std::int64_t first = frame_of(slot), last = frame_of(end - 1);
      problem(FrameProblemKind::missing, first, last - first + 1, "",
              (first == last ? "frame " + std::to_string(first) + " has no file"
                             : "frames " + std::to_string(first) + ".." + std::to_string(last) +
                                   " have no files") +
                  ": left empty");
      slot = end;
    }
  }

  int majority_keypoints() const {
    std::map<int, int> files_per_count;
    for (int k : keypoints_) {
      if (k != 0) ++files_per_count[k];
    }
    int best = 0, best_files = 0;
    for (const auto& [count, n] : files_per_count) {
      if (n > best_files) best = count, best_files = n;
    }
    return best;
  }

  void settle_layout() {
    const int count = majority_keypoints();
    for (std::size_t slot = 0; slot < out_.frames.size(); ++slot) {
      if (keypoints_[slot] == 0 || keypoints_[slot] == count) continue;
      problem(FrameProblemKind::layout_mismatch, frame_of(slot), 1, files_[slot],
              files_[slot] + ": " + std::to_string(keypoints_[slot]) +
                  " keypoints per person, but most files have " + std::to_string(count) +
                  ": left empty");
      out_.frames[slot].people.clear();
    }
    if (count == 25 && options_.body25 == Body25Choice::detect) {
      for (const auto& frame : out_.frames) out_.votes.add(vote_body25_variant(frame));
    }
    out_.layout = resolve_layout(count, options_.body25, out_.votes);
  }

  void stamp_headers(const std::string& stream) {
    for (std::size_t slot = 0; slot < out_.frames.size(); ++slot) {
      People2D& f = out_.frames[slot];
      f.layout = out_.layout;
      f.header.stream = stream;
      f.header.seq = slot;
      f.header.frame = frame_of(slot);
    }
  }

  const OpenPoseOptions& options_;
  OpenPoseSequence out_;
  std::vector<int> keypoints_;      // per slot: keypoints per person, 0 when empty or bad
  std::vector<std::string> files_;  // per slot: the file read, empty when none
};

}  // namespace

OpenPoseSequence read_openpose_folder(const std::filesystem::path& folder,
                                      const OpenPoseOptions& options) {
  const std::vector<FrameFile> files = list_frame_files(folder);
  if (files.empty()) {
    throw InputError(folder.string(),
                     "no numbered *.json file (expected OpenPose output such as "
                     "video_000000000000_keypoints.json)");
  }
  const std::int64_t first = files.front().number, last = files.back().number;
  if (last - first >= options.max_frames) {
    throw InputError(folder.string(), "frame numbers " + std::to_string(first) + ".." +
                                          std::to_string(last) + " span more than " +
                                          std::to_string(options.max_frames) +
                                          " frames (OpenPoseOptions::max_frames)");
  }
  FolderReader reader(options, first, static_cast<std::size_t>(last - first + 1));
  return reader.read(files, folder.string());
}

std::string openpose_json_text(const People2D& frame) {
  json people = json::array();
  for (const Person2D& p : frame.people) {
    json keypoints = json::array();
    for (const Keypoint2D& k : p.joints) {
      const bool seen = k.confidence > 0.0f && std::isfinite(k.x) && std::isfinite(k.y) &&
                        std::isfinite(k.confidence);
      keypoints.push_back(seen ? k.x : 0.0f);
      keypoints.push_back(seen ? k.y : 0.0f);
      keypoints.push_back(seen ? k.confidence : 0.0f);
    }
    people.push_back({{"person_id", json::array({p.id})},
                      {"pose_keypoints_2d", std::move(keypoints)},
                      {"face_keypoints_2d", json::array()},
                      {"hand_left_keypoints_2d", json::array()},
                      {"hand_right_keypoints_2d", json::array()}});
  }
  return json{{"version", 1.3}, {"people", std::move(people)}}.dump();
}

std::filesystem::path openpose_file_name(const std::filesystem::path& folder,
                                         const std::string& stem, std::int64_t number) {
  char digits[32];
  std::snprintf(digits, sizeof digits, "%012lld", static_cast<long long>(number));
  return folder / (stem + "_" + digits + "_keypoints.json");
}

void write_openpose_file(const std::filesystem::path& file, const People2D& frame) {
  std::filesystem::path temporary = file;
  temporary += ".partial";
  {
    std::ofstream out(temporary, std::ios::binary);
    out << openpose_json_text(frame) << "\n";
    if (!out.flush()) throw std::runtime_error("cannot write " + temporary.string());
  }
  std::error_code ec;
  std::filesystem::rename(temporary, file, ec);
  if (ec) throw std::runtime_error("cannot write " + file.string() + ": " + ec.message());
}

}  // namespace mocap::io
