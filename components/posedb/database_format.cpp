#include "posedb/database_format.hpp"

#include <cstring>
#include <stdexcept>

#include <zlib.h>
#include <nlohmann/json.hpp>

namespace mocap::posedb::format {
namespace {

using nlohmann::json;

motion::Channel channel_from_name(const std::string& name) {
  for (auto c :
       {motion::Channel::Xposition, motion::Channel::Yposition, motion::Channel::Zposition,
        motion::Channel::Xrotation, motion::Channel::Yrotation, motion::Channel::Zrotation}) {
    if (name == motion::channel_name(c)) return c;
  }
  throw std::runtime_error("unknown channel '" + name + "'");
}

json skeleton_to_json(const motion::Skeleton& s) {
  json joints = json::array();
  for (const auto& j : s.joints) {
    json channels = json::array();
    for (auto c : j.channels) channels.push_back(motion::channel_name(c));
    joints.push_back({{"name", j.name},
                      {"parent", j.parent},
                      {"offset", {j.offset.x, j.offset.y, j.offset.z}},
                      {"channels", channels},
                      {"end_site", j.end_site}});
  }
  return joints;
}

motion::Skeleton skeleton_from_json(const json& joints) {
  motion::Skeleton s;
  for (const auto& j : joints) {
    motion::SkeletonJoint joint;
    joint.name = j.at("name").get<std::string>();
    joint.parent = j.at("parent").get<int>();
    if (joint.parent < -1 || joint.parent >= s.joint_count()) {
      throw std::runtime_error("joint '" + joint.name + "' has an invalid parent");
    }
    const auto& o = j.at("offset");
    joint.offset = {o.at(0).get<float>(), o.at(1).get<float>(), o.at(2).get<float>()};
    for (const auto& c : j.at("channels"))
      joint.channels.push_back(channel_from_name(c.get<std::string>()));
    if (joint.channels.size() > 6)
      throw std::runtime_error("joint '" + joint.name + "' has more than 6 channels");
    joint.end_site = j.at("end_site").get<bool>();
    s.joints.push_back(std::move(joint));
  }
  s.assign_channel_slots();
  return s;
}

}  // namespace

std::array<char, 8> tag(const char* name) {
  std::array<char, 8> t{};
  std::memcpy(t.data(), name, strnlen(name, t.size()));
  return t;
}

std::uint32_t crc32_of(const void* data, std::uint64_t size) {
  return static_cast<std::uint32_t>(crc32_z(0L, static_cast<const Bytef*>(data), size));
}

std::string build_info_to_json(const BuildInfo& b) {
  const json j = {{"fps", b.fps},
                  {"scaling", std::string(scaling_name(b.scaling))},
                  {"body", std::string(body_choice_name(b.body))},
                  {"views",
                   {{"yaw_steps", b.views.yaw_steps},
                    {"heights_m", b.views.heights_m},
                    {"distance_m", b.views.distance_m},
                    {"root_height_m", b.views.root_height_m}}},
                  {"clusters", b.clusters},
                  {"seed", b.seed},
                  {"created", b.created},
                  {"command", b.command},
                  {"build_seconds", b.build_seconds}};
  // The command and the clips' names and sources hold paths, which may hold any byte: bytes that
  // are not UTF-8 become U+FFFD rather than failing the build at its end.
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

BuildInfo build_info_from_json(const std::string& text) {
  const json j = json::parse(text);
  BuildInfo b;
  b.fps = j.at("fps").get<double>();
  if (!parse_scaling(j.at("scaling").get<std::string>(), b.scaling))
    throw std::runtime_error("unknown scaling");
  if (j.contains("body") && !parse_body_choice(j.at("body").get<std::string>(), b.body))
    throw std::runtime_error("unknown body '" + j.at("body").get<std::string>() + "'");
  const auto& v = j.at("views");
  b.views.yaw_steps = v.at("yaw_steps").get<int>();
  b.views.heights_m = v.at("heights_m").get<std::vector<float>>();
  b.views.distance_m = v.at("distance_m").get<float>();
  b.views.root_height_m = v.at("root_height_m").get<float>();
  b.clusters = j.at("clusters").get<int>();
  b.seed = j.at("seed").get<std::uint64_t>();
  b.created = j.at("created").get<std::string>();
  b.command = j.at("command").get<std::string>();
  b.build_seconds = j.at("build_seconds").get<double>();
  return b;
}

std::string clips_to_json(const std::vector<ClipInfo>& clips) {
  json out = json::array();
  for (const auto& c : clips) {
    out.push_back({{"name", c.name},
                   {"source", c.source},
                   {"family", c.family},
                   {"mapping", c.mapping},
                   {"source_fps", c.source_fps},
                   {"source_first_frame", c.source_first_frame},
                   {"first_frame", c.first_frame},
                   {"frame_count", c.frame_count},
                   {"rotation_offset", c.rotation_offset},
                   {"metres_per_unit", c.metres_per_unit},
                   {"skeleton", skeleton_to_json(c.skeleton)}});
  }
  return out.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::vector<ClipInfo> clips_from_json(const std::string& text) {
  const json j = json::parse(text);
  std::vector<ClipInfo> clips;
  for (const auto& c : j) {
    ClipInfo info;
    info.name = c.at("name").get<std::string>();
    info.source = c.at("source").get<std::string>();
    info.family = c.at("family").get<std::string>();
    info.mapping = c.at("mapping").get<std::string>();
    info.source_fps = c.at("source_fps").get<double>();
    info.source_first_frame = c.at("source_first_frame").get<std::uint32_t>();
    info.first_frame = c.at("first_frame").get<std::uint32_t>();
    info.frame_count = c.at("frame_count").get<std::uint32_t>();
    info.rotation_offset = c.at("rotation_offset").get<std::uint64_t>();
    info.metres_per_unit = c.at("metres_per_unit").get<float>();
    info.skeleton = skeleton_from_json(c.at("skeleton"));
    clips.push_back(std::move(info));
  }
  return clips;
}

}  // namespace mocap::posedb::format
