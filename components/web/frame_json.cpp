#include "web/frame_json.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

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

Json vector_json(const glm::dvec3& v, double scale) {
  return {rounded(v.x, scale), rounded(v.y, scale), rounded(v.z, scale)};
}

Json people_json(const People3D& frame, const GroundPlane& ground) {
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
  return people;
}

Json frame_head(const People3D& frame, std::optional<double> time) {
  return {
      {"type", "frame"},
      {"frame", frame.header.frame},
      {"time", rounded(time.value_or(static_cast<double>(frame.header.capture_ns) * 1e-9), 1000)}};
}

Json ground_json(bool known, const GroundPlane& ground) {
  return {{"known", known},
          {"normal", vector_json(ground.normal, 1e4)},
          {"offset", rounded(ground.offset, 1000)}};
}

// In float, as the viewer always had them.
Json intrinsics_json(const camera::Camera& c) {
  return {{"width", c.width},
          {"height", c.height},
          {"fx", rounded(static_cast<float>(c.fx), 10)},
          {"fy", rounded(static_cast<float>(c.fy), 10)},
          {"cx", rounded(static_cast<float>(c.cx), 10)},
          {"cy", rounded(static_cast<float>(c.cy), 10)}};
}

void add_playback(Json& out, const std::optional<Playback>& playback) {
  if (!playback) return;
  out["playback"] = {{"index", playback->index},
                     {"count", playback->count},
                     {"playing", playback->playing},
                     {"speed", playback->speed},
                     {"duration", rounded(playback->duration, 1000)}};
}

// A rig camera at its pose: rotation camera -> world (Rᵀ, row-major) and its centre.
Json posed_camera_json(const camera::Camera& c) {
  Json out = intrinsics_json(c);
  out["name"] = c.name;
  Json rotation = Json::array();
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) rotation.push_back(rounded(c.rotation[row][col], 1e6));
  out["rotation"] = rotation;  // Rᵀ[row][col] = R[col][row] = glm rotation[row][col]
  out["position"] = vector_json(c.centre(), 1e4);
  return out;
}

// The world's up: the floor's normal, else opposite the cameras' mean y axis ("down" in the image),
// else from the people's hips to their necks.
glm::dvec3 world_up(const People3D& frame, const camera::Rig& rig) {
  if (frame.has_ground) return frame.ground.normal;
  if (rig.floor) return rig.floor->normal;
  if (const std::optional<glm::dvec3> up = camera::cameras_up(rig)) return *up;
  glm::dvec3 up(0.0);  // no camera: people stand upright
  for (const Person3D& p : frame.people)
    up += glm::dvec3(p.positions[index(Joint::neck)] - p.positions[index(Joint::root)]);
  const double length = glm::length(up);
  return length > 1e-9 && std::isfinite(length) ? up / length : glm::dvec3(0.0, -1.0, 0.0);
}

// Not known: level with the lowest ankle in view, or 1.6 m below the lowest camera.
GroundPlane assumed_world_floor(const People3D& frame, const camera::Rig& rig,
                                const glm::dvec3& up) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const Person3D& p : frame.people) {
    if (!p.placed) continue;
    for (const Joint j : {Joint::left_ankle, Joint::right_ankle}) {
      const double h = glm::dot(up, glm::dvec3(p.positions[index(j)] + p.root.translation));
      if (std::isfinite(h)) lowest = std::min(lowest, h);
    }
  }
  if (!std::isfinite(lowest)) {
    for (const camera::Camera& c : rig.cameras)
      lowest = std::min(lowest, glm::dot(up, c.centre()) - 1.6);
  }
  return {up, std::isfinite(lowest) ? -lowest : 0.0};
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
  Json out = frame_head(frame, time);
  out["people"] = people_json(frame, ground);
  out["ground"] = ground_json(frame.has_ground, ground);
  Json cam = {{"known", camera.has_value()}};
  if (camera) {
    cam["assumed"] = camera->assumed;
    cam.update(intrinsics_json(camera->camera));
  }
  out["camera"] = cam;
  add_playback(out, playback);
  return out.dump();
}

std::string frame_json(const People3D& frame, const camera::Rig& rig,
                       const std::optional<Playback>& playback, std::optional<double> time) {
  const glm::dvec3 up = world_up(frame, rig);
  const bool floor_known = frame.has_ground || rig.floor.has_value();
  const GroundPlane ground = frame.has_ground ? frame.ground
                             : rig.floor      ? *rig.floor
                                              : assumed_world_floor(frame, rig, up);
  Json out = frame_head(frame, time);
  out["people"] = people_json(frame, ground);
  out["ground"] = ground_json(floor_known, ground);
  out["world"] = true;
  out["up"] = vector_json(up, 1e4);
  Json cameras = Json::array();
  for (const camera::Camera& c : rig.cameras) cameras.push_back(posed_camera_json(c));
  out["cameras"] = cameras;
  Json first = {{"known", !rig.cameras.empty()}};
  if (!rig.cameras.empty()) {
    first["assumed"] = false;
    first.update(intrinsics_json(rig.cameras.front()));
  }
  out["camera"] = first;
  add_playback(out, playback);
  return out.dump();
}

}  // namespace mocap::web
