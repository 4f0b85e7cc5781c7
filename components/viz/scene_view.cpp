#include "viz/scene_view.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <glm/gtx/quaternion.hpp>

#include "core/scene.hpp"

namespace mocap::viz {
namespace {

constexpr float kMargin = 0.3f;             // metres around the people
constexpr glm::vec2 kSmallest{2.5f, 2.2f};  // view metres: one person fills no more
constexpr float kShrinkPerFrame = 0.05f;    // framing shrinks this much of the way
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

bool finite(glm::vec3 p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

// The unplaced people's slots: left to right as their boxes stand in the 2D input, people
// without a box there after them, by id.
std::map<const Person3D*, std::size_t> row_slots(const People3D& people, const People2D& people2d) {
  std::map<int, float> box_centre;
  for (const Person2D& p : people2d.people) box_centre[p.id] = p.box.x + p.box.width / 2.0f;
  auto key = [&](const Person3D* p) {
    const auto it = box_centre.find(p->id);
    return it == box_centre.end() ? std::make_pair(1, float(p->id)) : std::make_pair(0, it->second);
  };
  std::vector<const Person3D*> row;
  for (const Person3D& p : people.people)
    if (!p.placed) row.push_back(&p);
  std::stable_sort(row.begin(), row.end(),
                   [&](const Person3D* a, const Person3D* b) { return key(a) < key(b); });
  std::map<const Person3D*, std::size_t> slots;
  for (std::size_t i = 0; i < row.size(); ++i) slots[row[i]] = i;
  return slots;
}

}  // namespace

GroundPlane scene_floor(const People3D& people) {
  if (people.has_ground) return people.ground;
  float lowest = -std::numeric_limits<float>::infinity();  // camera y points down
  for (const Person3D& p : people.people) {
    if (!p.placed) continue;
    for (Joint foot : {Joint::left_ankle, Joint::right_ankle}) {
      const float y = p.root.translation.y + p.positions[static_cast<std::size_t>(index(foot))].y;
      if (std::isfinite(y)) lowest = std::max(lowest, y);
    }
  }
  if (std::isfinite(lowest)) return GroundPlane{{0.0f, -1.0f, 0.0f}, lowest};
  return assumed_ground();
}

std::vector<ScenePerson> scene_people(const People3D& people, const People2D& people2d,
                                      const GroundPlane& floor, float spacing_m) {
  const auto slots = row_slots(people, people2d);
  std::vector<ScenePerson> out;
  out.reserve(people.people.size());
  for (const Person3D& p : people.people) {
    ScenePerson s;
    s.id = p.id;
    s.placed = p.placed;
    if (p.placed) {
      for (int j = 0; j < kBodyJoints; ++j)
        s.joints[static_cast<std::size_t>(j)] =
            p.root.translation + p.positions[static_cast<std::size_t>(j)];
    } else {
      const auto body = upright_positions(p, floor.normal);
      const glm::vec3 root = body[static_cast<std::size_t>(index(Joint::root))];
      const glm::vec3 spot = display_root(floor, slots.at(&p), slots.size(), spacing_m);
      for (int j = 0; j < kBodyJoints; ++j)
        s.joints[static_cast<std::size_t>(j)] = spot + body[static_cast<std::size_t>(j)] - root;
    }
    for (glm::vec3& joint : s.joints)
      if (!finite(joint)) joint = glm::vec3(kNaN);
    out.push_back(s);
  }
  return out;
}

std::array<glm::vec3, kBodyJoints> upright_positions(const Person3D& person, glm::vec3 up) {
  const glm::vec3 body_up = person.root.rotation * glm::vec3(0.0f, 1.0f, 0.0f);
  std::array<glm::vec3, kBodyJoints> out = person.positions;
  // No camera looks at the world upside down: such an "up" means the rotation was not set.
  if (!(glm::dot(body_up, up) > 0.0f)) return out;
  const glm::quat level = glm::rotation(glm::normalize(body_up), glm::normalize(up));
  for (glm::vec3& p : out) p = level * p;
  return out;
}

SceneCamera::SceneCamera(int width, int height, int top, float yaw_deg, float pitch_deg)
    : width_(width),
      height_(height),
      top_(top),
      yaw_(glm::radians(yaw_deg)),
      pitch_(glm::radians(pitch_deg)) {
  if (width < 16 || height < 16 || top < 0 || top > height / 2)
    throw std::invalid_argument("scene camera: panel too small");
  floor_ = assumed_ground();
  low_ = {-kSmallest.x / 2.0f, -2.0f};
  high_ = {kSmallest.x / 2.0f, -2.0f + kSmallest.y};
}

void SceneCamera::follow(const GroundPlane& floor, const std::vector<ScenePerson>& people) {
  // The floor's axes: up is its normal; ahead is the real camera's view direction laid on the
  // floor (or, for a camera looking straight down, the image's up laid on it); right completes
  // them as the camera's x does.
  floor_ = floor;
  up_ = glm::normalize(floor.normal);
  glm::vec3 ahead = glm::vec3(0, 0, 1) - up_.z * up_;
  if (glm::length(ahead) < 1e-3f) ahead = glm::vec3(0, -1, 0) - up_.y * up_;
  ahead_ = glm::normalize(ahead);
  right_ = glm::cross(ahead_, up_);

  glm::vec2 low(std::numeric_limits<float>::infinity()), high(-low);
  for (const ScenePerson& p : people) {
    for (const glm::vec3& joint : p.joints) {
      if (!finite(joint)) continue;
      const glm::vec3 v = view_of(floor_coordinates(joint));
      low = glm::min(low, glm::vec2(v));
      high = glm::max(high, glm::vec2(v));
    }
  }
  if (!(low.x <= high.x)) return;  // nobody: the view stays
  low -= kMargin;
  high += kMargin;
  const glm::vec2 grow = glm::max(kSmallest - (high - low), glm::vec2(0.0f)) / 2.0f;
  low -= grow;
  high += grow;
  if (!framed_) {
    low_ = low, high_ = high, framed_ = true;
    return;
  }
  // Out at once (nobody leaves the panel), in slowly (no jump when someone goes).
  for (int axis = 0; axis < 2; ++axis) {
    low_[axis] = low[axis] < low_[axis] ? low[axis]
                                        : low_[axis] + kShrinkPerFrame * (low[axis] - low_[axis]);
    high_[axis] = high[axis] > high_[axis]
                      ? high[axis]
                      : high_[axis] + kShrinkPerFrame * (high[axis] - high_[axis]);
  }
}

glm::vec3 SceneCamera::floor_coordinates(glm::vec3 p) const {
  return {glm::dot(p, right_), glm::dot(p, up_) + floor_.offset, glm::dot(p, ahead_)};
}

glm::vec3 SceneCamera::view_of(glm::vec3 f) const {
  // Turned about the vertical by the yaw, then tilted down by the pitch; y down as in images.
  const float x = std::cos(yaw_) * f.x + std::sin(yaw_) * f.z;
  const float z = -std::sin(yaw_) * f.x + std::cos(yaw_) * f.z;
  const float y = -std::cos(pitch_) * f.y - std::sin(pitch_) * z;
  const float depth = std::cos(pitch_) * z - std::sin(pitch_) * f.y;
  return {x, y, depth};
}

float SceneCamera::pixels_per_metre() const {
  const glm::vec2 size = high_ - low_;
  return std::min(float(width_) / size.x, float(height_ - top_) / size.y);
}

glm::vec2 SceneCamera::project_floor(glm::vec3 f) const {
  const glm::vec3 v = view_of(f);
  const glm::vec2 panel_centre(float(width_) / 2.0f, float(top_ + height_) / 2.0f);
  return panel_centre + (glm::vec2(v) - (low_ + high_) / 2.0f) * pixels_per_metre();
}

glm::vec2 SceneCamera::project(glm::vec3 camera_point) const {
  return project_floor(floor_coordinates(camera_point));
}

float SceneCamera::depth(glm::vec3 camera_point) const {
  return view_of(floor_coordinates(camera_point)).z;
}

std::array<float, 4> SceneCamera::visible_floor(float step) const {
  // The panel's corners back on the floor (height 0): view y = -sin(pitch) * z there.
  const float scale = pixels_per_metre();
  const glm::vec2 centre = (low_ + high_) / 2.0f;
  const glm::vec2 panel_centre(float(width_) / 2.0f, float(top_ + height_) / 2.0f);
  const float sin_pitch = std::sin(pitch_);
  std::array<float, 4> box = {
      std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
      -std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
  for (float px : {0.0f, float(width_)}) {
    for (float py : {float(top_), float(height_)}) {
      const glm::vec2 v = centre + (glm::vec2(px, py) - panel_centre) / scale;
      // A floor seen nearly edge-on reaches far: at most 60 m of it.
      const float z =
          std::abs(sin_pitch) > 1e-3f ? std::clamp(-v.y / sin_pitch, -60.0f, 60.0f) : 0.0f;
      const float x = std::cos(yaw_) * v.x - std::sin(yaw_) * z;
      const float ahead = std::sin(yaw_) * v.x + std::cos(yaw_) * z;
      box = {std::min(box[0], x), std::min(box[1], ahead), std::max(box[2], x),
             std::max(box[3], ahead)};
    }
  }
  box[0] = std::floor(box[0] / step) * step;
  box[1] = std::floor(box[1] / step) * step;
  box[2] = std::ceil(box[2] / step) * step;
  box[3] = std::ceil(box[3] / step) * step;
  return box;
}

}  // namespace mocap::viz
