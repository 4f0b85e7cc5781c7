#include "web/frame_json.hpp"

#include <cmath>

#include <nlohmann/json.hpp>

namespace mocap::web {
namespace {

using Json = nlohmann::json;

Json millimetres(float metres) {
  if (!std::isfinite(metres)) return nullptr;
  return std::lround(static_cast<double>(metres) * 1000.0);
}

Json rounded(double v, double scale) {
  if (!std::isfinite(v)) return nullptr;
  return std::round(v * scale) / scale;
}

}  // namespace

std::string hello_json(const std::string& title) {
  Json bones = Json::array();
  for (int j = 0; j < kBodyJoints; ++j) {
    if (kJointParent[static_cast<std::size_t>(j)] >= 0)
      bones.push_back({kJointParent[static_cast<std::size_t>(j)], j});
  }
  Json names = Json::array();
  for (const auto name : kJointNames) names.push_back(std::string(name));
  // The title is often a file name, which may hold bytes that are not UTF-8.
  return Json{{"type", "hello"}, {"title", title}, {"joints", names}, {"bones", bones}}.dump(
      -1, ' ', false, Json::error_handler_t::replace);
}

std::string frame_json(const People3D& frame, const std::optional<ShownCamera>& camera,
                       const std::optional<Playback>& playback, std::optional<double> time) {
  const GroundPlane ground = frame.has_ground ? frame.ground : assumed_ground();
  std::size_t unplaced = 0;
  for (const Person3D& p : frame.people) unplaced += p.placed ? 0 : 1;
  Json people = Json::array();
  std::size_t slot = 0;
  for (const Person3D& p : frame.people) {
    const glm::vec3 root = p.positions[index(Joint::root)];
    const glm::vec3 shift =
        p.placed ? p.root.translation : display_root(ground, slot++, unplaced) - root;
    Json joints = Json::array();
    for (const glm::vec3& position : p.positions) {
      const glm::vec3 v = position + shift;
      joints.insert(joints.end(), {millimetres(v.x), millimetres(v.y), millimetres(v.z)});
    }
    Json keypoints = Json::array();
    for (const Keypoint2D& k : p.keypoints) {
      const bool ok = k.confidence > 0 && std::isfinite(k.x) && std::isfinite(k.y);
      keypoints.insert(keypoints.end(),
                       {ok ? rounded(k.x, 10) : Json(0), ok ? rounded(k.y, 10) : Json(0),
                        ok ? rounded(k.confidence, 100) : Json(0)});
    }
    people.push_back(
        {{"id", p.id}, {"placed", p.placed}, {"joints", joints}, {"keypoints", keypoints}});
  }
  Json out = {
      {"type", "frame"},
      {"frame", frame.header.frame},
      {"time", rounded(time.value_or(static_cast<double>(frame.header.capture_ns) * 1e-9), 1000)},
      {"people", people},
      {"ground",
       {{"known", frame.has_ground},
        {"normal",
         {rounded(ground.normal.x, 1e4), rounded(ground.normal.y, 1e4),
          rounded(ground.normal.z, 1e4)}},
        {"offset", rounded(ground.offset, 1000)}}}};
  Json cam = {{"known", camera.has_value()}};
  if (camera) {
    // In float, as the viewer always had them.
    const camera::Camera& c = camera->camera;
    cam.update({{"assumed", camera->assumed},
                {"width", c.width},
                {"height", c.height},
                {"fx", rounded(static_cast<float>(c.fx), 10)},
                {"fy", rounded(static_cast<float>(c.fy), 10)},
                {"cx", rounded(static_cast<float>(c.cx), 10)},
                {"cy", rounded(static_cast<float>(c.cy), 10)}});
  }
  out["camera"] = cam;
  if (playback) {
    out["playback"] = {{"index", playback->index},
                       {"count", playback->count},
                       {"playing", playback->playing},
                       {"speed", playback->speed},
                       {"duration", rounded(playback->duration, 1000)}};
  }
  return out.dump();
}

}  // namespace mocap::web
