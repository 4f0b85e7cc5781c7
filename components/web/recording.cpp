#include "web/recording.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <istream>

#include <nlohmann/json.hpp>

#include "core/input_error.hpp"

namespace mocap::web {
namespace {

using Json = nlohmann::json;

glm::vec3 vec3_of(const Json& value, const std::string& what) {
  if (!value.is_array() || value.size() != 3 || !value[0].is_number() || !value[1].is_number() ||
      !value[2].is_number())
    throw std::invalid_argument(what + " is not [x, y, z]");
  return {value[0].get<float>(), value[1].get<float>(), value[2].get<float>()};
}

std::array<glm::vec3, kBodyJoints> joints_of(const Json& joints, const std::string& what) {
  if (!joints.is_object()) throw std::invalid_argument(what + " is not an object");
  std::array<glm::vec3, kBodyJoints> out{};
  for (int j = 0; j < kBodyJoints; ++j) {
    const std::string name(kJointNames[static_cast<std::size_t>(j)]);
    const auto it = joints.find(name);
    if (it == joints.end()) throw std::invalid_argument(what + " has no joint '" + name + "'");
    out[static_cast<std::size_t>(j)] = vec3_of(*it, what + "." + name);
  }
  return out;
}

// sink.jsonl's flat [x, y, confidence] x 15; a missing keypoint stays at confidence 0.
std::array<Keypoint2D, kBodyJoints> keypoints_of(const Json& flat, const std::string& what) {
  if (!flat.is_array() || flat.size() != 3 * kBodyJoints)
    throw std::invalid_argument(what + " keypoints are not 15 x [x, y, confidence]");
  std::array<Keypoint2D, kBodyJoints> out{};
  for (std::size_t j = 0; j < out.size(); ++j) {
    for (std::size_t c = 0; c < 3; ++c)
      if (!flat[3 * j + c].is_number())
        throw std::invalid_argument(what + " keypoints hold something not a number");
    out[j] = {flat[3 * j].get<float>(), flat[3 * j + 1].get<float>(), flat[3 * j + 2].get<float>()};
    if (!(out[j].confidence > 0) || !std::isfinite(out[j].x) || !std::isfinite(out[j].y))
      out[j] = {};
  }
  return out;
}

People3D frame_of(const Json& line, std::int64_t number) {
  if (!line.is_object()) throw std::invalid_argument("not a JSON object");
  People3D frame;
  const auto f = line.find("frame");
  frame.header.frame = f != line.end() && f->is_number_integer() ? f->get<std::int64_t>() : number;
  frame.header.seq = static_cast<std::uint64_t>(number);
  const auto people = line.find("people");
  if (people == line.end() || !people->is_array()) throw std::invalid_argument("no 'people' array");
  for (const Json& p : *people) {
    Person3D person;
    if (!p.is_object() || !p.contains("id") || !p["id"].is_number_integer())
      throw std::invalid_argument("a person without an integer 'id'");
    person.id = p["id"].get<int>();
    const std::string what = "person " + std::to_string(person.id);
    person.positions = joints_of(p.value("joints", Json()), what + " joints");
    const auto abs = p.find("joints_abs"), world = p.find("joints_world");
    if (abs != p.end() && world != p.end())
      throw std::invalid_argument(what + " has both joints_abs and joints_world");
    if (world != p.end()) {
      if (!frame.people.empty() && !frame.frame.is_world())
        throw std::invalid_argument(what + " has joints_world, the people before it have not");
      frame.frame = CoordinateFrame::world();
    } else if (frame.frame.is_world()) {
      throw std::invalid_argument(what + " has no joints_world, the people before it have");
    }
    if (const auto placed_at = world != p.end() ? world : abs; placed_at != p.end()) {
      const auto placed =
          joints_of(*placed_at, what + (world != p.end() ? " joints_world" : " joints_abs"));
      person.placed = true;
      person.root.translation = placed[index(Joint::root)] - person.positions[index(Joint::root)];
    }
    if (const auto kp = p.find("keypoints"); kp != p.end())
      person.keypoints = keypoints_of(*kp, what);
    frame.people.push_back(person);
  }
  if (const auto ground = line.find("ground"); ground != line.end()) {
    if (!ground->is_object() || !ground->contains("offset") || !(*ground)["offset"].is_number())
      throw std::invalid_argument("'ground' without a numeric 'offset'");
    frame.ground.normal = glm::dvec3(vec3_of(ground->value("normal", Json()), "ground normal"));
    frame.ground.offset = (*ground)["offset"].get<double>();
    const double length = glm::length(frame.ground.normal);
    if (!(length > 0.5 && length < 2.0)) throw std::invalid_argument("ground normal not a unit");
    frame.has_ground = true;
  }
  return frame;
}

// A file is in one frame: people with joints_world (a rig's world) and people with joints_abs
// (a camera's frame) cannot be drawn together. Remembers the first line of each.
struct FrameKinds {
  long world_line = 0, camera_line = 0;

  void add(const People3D& frame, long line) {
    const bool camera_placed =
        !frame.frame.is_world() && std::any_of(frame.people.begin(), frame.people.end(),
                                               [](const Person3D& p) { return p.placed; });
    if (frame.frame.is_world() && world_line == 0) world_line = line;
    if (camera_placed && camera_line == 0) camera_line = line;
    if (world_line > 0 && camera_line > 0)
      throw std::invalid_argument(
          world_line > camera_line
              ? "joints_world, but line " + std::to_string(camera_line) + " has joints_abs"
              : "joints_abs, but line " + std::to_string(world_line) + " has joints_world");
  }
};

}  // namespace

Recording read_poses_jsonl(const std::string& path, double fps) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open the file");
  return parse_poses_jsonl(in, path, fps);
}

Recording parse_poses_jsonl(std::istream& in, const std::string& path, double fps) {
  Recording out;
  FrameKinds kinds;
  bool times_ok = true;
  std::string text;
  for (long line = 1; std::getline(in, text); ++line) {
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      const Json json = Json::parse(text);
      People3D frame = frame_of(json, static_cast<std::int64_t>(out.frames.size()));
      kinds.add(frame, line);
      out.frames.push_back(std::move(frame));
      const auto t = json.find("time");
      const bool has_time = t != json.end() && t->is_number() && std::isfinite(t->get<double>());
      const double time = has_time ? t->get<double>() : 0.0;
      if (!has_time || (!out.times.empty() && time < out.times.back())) times_ok = false;
      out.times.push_back(time);
    } catch (const std::exception& e) {
      if (in.eof() && !out.frames.empty()) {  // no newline after it: cut by a kill
        out.cut_last_line = true;
        break;
      }
      throw InputError(path, line, std::string("not a poses.jsonl line: ") + e.what());
    }
  }
  if (in.bad()) throw InputError(path, "read error");
  if (out.frames.empty()) throw InputError(path, "no frames (an empty poses.jsonl)");
  out.world = kinds.world_line > 0;
  if (out.world)
    for (People3D& frame : out.frames) frame.frame = CoordinateFrame::world();
  const double first = out.times.front();
  // Beyond about 292 years nanoseconds do not fit: such a file plays with its frames `fps` apart.
  if (times_ok && !(out.times.back() - first < 9.2e9)) times_ok = false;
  for (std::size_t i = 0; i < out.times.size(); ++i) {
    out.times[i] = times_ok ? out.times[i] - first : static_cast<double>(i) / fps;
    out.frames[i].header.capture_ns = static_cast<std::int64_t>(std::llround(out.times[i] * 1e9));
  }
  return out;
}

Player::Player(std::vector<double> times) : times_(std::move(times)) {}

void Player::seek(std::size_t index) {
  if (times_.empty()) return;
  index_ = std::min(index, times_.size() - 1);
  clock_ = times_[index_];
}

void Player::set_speed(double speed) {
  if (std::isfinite(speed)) speed_ = std::clamp(speed, 0.05, 16.0);
}

std::size_t Player::advance(double seconds) {
  if (times_.size() < 2 || !playing_ || !(seconds > 0)) return index_;
  // The last frame is shown for one mean frame interval before the recording starts again.
  const double period =
      duration() * static_cast<double>(times_.size()) / static_cast<double>(times_.size() - 1);
  clock_ += seconds * speed_;
  if (period > 0 && clock_ >= period) clock_ = std::fmod(clock_, period);
  const auto after = std::upper_bound(times_.begin(), times_.end(), clock_);
  index_ = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, after - times_.begin() - 1));
  return index_;
}

bool Player::apply(const std::string& message) {
  const Json json = Json::parse(message, nullptr, false);
  if (!json.is_object() || !json.contains("cmd") || !json["cmd"].is_string()) return false;
  const std::string cmd = json["cmd"].get<std::string>();
  if (cmd == "play") {
    play();
  } else if (cmd == "pause") {
    pause();
  } else if (cmd == "seek" && json.contains("index") && json["index"].is_number()) {
    const double i = json["index"].get<double>();
    if (!std::isfinite(i)) return false;
    seek(static_cast<std::size_t>(std::clamp(i, 0.0, 1e12)));
  } else if (cmd == "speed" && json.contains("value") && json["value"].is_number()) {
    set_speed(json["value"].get<double>());
  } else {
    return false;
  }
  return true;
}

}  // namespace mocap::web
