#include "viz/overlay_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/gtx/quaternion.hpp>
#include <opencv2/imgproc.hpp>

#include "viz/image_convert.hpp"

namespace mocap::viz {
namespace {

constexpr int kMaxSide = 16384;
constexpr float kFloorFallback = 0.9f;  // metres below the root when no foot is known

cv::Scalar bgr(Rgb c) { return {double(c.b), double(c.g), double(c.r)}; }
cv::Point pixel(glm::vec2 p) { return {cvRound(p.x), cvRound(p.y)}; }
bool finite(glm::vec2 p) { return std::isfinite(p.x) && std::isfinite(p.y); }
bool finite(glm::vec3 p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

// Text that stays readable on any background: a dark outline under the colour.
void put_text(cv::Mat& image, const std::string& text, glm::vec2 at, double scale, Rgb colour) {
  cv::putText(image, text, pixel(at), cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 3,
              cv::LINE_AA);
  cv::putText(image, text, pixel(at), cv::FONT_HERSHEY_SIMPLEX, scale, bgr(colour), 1, cv::LINE_AA);
}

Rgb from_hsv(float hue_deg, float saturation, float value) {
  const float c = value * saturation;
  const float h = hue_deg / 60.0f;
  const float x = c * (1.0f - std::abs(std::fmod(h, 2.0f) - 1.0f));
  float r = 0, g = 0, b = 0;
  switch (static_cast<int>(h) % 6) {
    case 0:
      r = c, g = x;
      break;
    case 1:
      r = x, g = c;
      break;
    case 2:
      g = c, b = x;
      break;
    case 3:
      g = x, b = c;
      break;
    case 4:
      r = x, b = c;
      break;
    default:
      r = c, b = x;
      break;
  }
  const float m = value - c;
  auto byte = [m](float v) { return static_cast<std::uint8_t>(std::lround((v + m) * 255.0f)); };
  return {byte(r), byte(g), byte(b)};
}

// The 15 body joints of a 2D person in its layout, pixels; NaN where missing.
std::array<glm::vec2, kBodyJoints> body_of(const KeypointLayout& layout, const Person2D& person) {
  std::vector<float> keypoints;
  keypoints.reserve(person.joints.size() * 3);
  for (const Keypoint2D& k : person.joints)
    keypoints.insert(keypoints.end(), {k.x, k.y, k.confidence});
  std::array<glm::vec2, kBodyJoints> body;
  body.fill(glm::vec2(std::numeric_limits<float>::quiet_NaN()));
  if (keypoints.size() != layout.keypoints.size() * 3) return body;  // not of this layout
  std::array<float, kBodyJoints * 3> xyc{};
  to_body15(layout, keypoints, xyc);
  for (int j = 0; j < kBodyJoints; ++j) {
    if (xyc[3 * j + 2] > 0.0f) body[j] = glm::vec2(xyc[3 * j], xyc[3 * j + 1]);
  }
  return body;
}

// Bones of the 15-joint tree between the points that are present.
template <class Point, class Project>
void draw_skeleton(cv::Mat& image, const std::array<Point, kBodyJoints>& joints,
                   const Project& project, Rgb colour, int thickness) {
  for (int j = 0; j < kBodyJoints; ++j) {
    const int parent = kJointParent[j];
    if (parent < 0 || !finite(joints[j]) || !finite(joints[parent])) continue;
    cv::line(image, pixel(project(joints[j])), pixel(project(joints[parent])), bgr(colour),
             thickness, cv::LINE_AA);
  }
  for (const Point& p : joints) {
    if (finite(p))
      cv::circle(image, pixel(project(p)), thickness + 1, bgr(colour), -1, cv::LINE_AA);
  }
}

std::string frame_text(const OverlayLabel& label) {
  char text[64];
  if (label.fps > 0.0) {
    std::snprintf(text, sizeof text, "frame %lld   %.1f fps", static_cast<long long>(label.frame),
                  label.fps);
  } else {
    std::snprintf(text, sizeof text, "frame %lld", static_cast<long long>(label.frame));
  }
  return text;
}

void draw_people_2d(const OverlayRenderer& r, cv::Mat& left, const People2D& people,
                    int input_width, int input_height) {
  const KeypointLayout& keypoint_layout = layout(people.layout);
  auto project = [&](glm::vec2 p) { return r.left_point(p, input_width, input_height); };
  for (const Person2D& person : people.people) {
    const Rgb colour = id_colour(person.id);
    for (const Keypoint2D& k : person.joints) {
      const glm::vec2 p(k.x, k.y);
      if (k.confidence > 0.0f && finite(p))
        cv::circle(left, pixel(project(p)), 2, bgr(colour), -1, cv::LINE_AA);
    }
    draw_skeleton(left, body_of(keypoint_layout, person), project, colour, 2);
    const Box2D& b = person.box;
    if (b.width > 0 && b.height > 0) {
      const glm::vec2 corner = project({b.x, b.y});
      cv::rectangle(left, pixel(corner), pixel(project({b.x + b.width, b.y + b.height})),
                    bgr(colour), 1);
      put_text(left, person.id >= 0 ? std::to_string(person.id) : "?", corner + glm::vec2(2, -4),
               0.5, colour);
    }
  }
}

using Body3D = std::array<glm::vec3, kBodyJoints>;

float floor_height(const std::vector<Body3D>& bodies) {
  float floor = -std::numeric_limits<float>::infinity();
  for (const Body3D& b : bodies) {
    for (Joint foot : {Joint::left_ankle, Joint::right_ankle}) {
      const float y = b[static_cast<std::size_t>(index(foot))].y;
      if (std::isfinite(y)) floor = std::max(floor, y);
    }
  }
  return std::isfinite(floor) ? floor : kFloorFallback;
}

// Half-metre squares under the people, in the scene's axes (so the floor shows the view's turn),
// reaching half a metre and more beyond the row of people on every side.
void draw_floor(const OverlayRenderer& r, cv::Mat& right, float floor_y, int people) {
  const glm::vec2 panel(float(r.panel_width()), 0.0f);
  const float row = float(people - 1) / 2.0f * r.person_spacing_m();  // half the row's length
  const float yaw = glm::radians(r.view_yaw_deg());
  auto half_metres = [](float metres) { return std::ceil(2.0f * metres + 1.0f) / 2.0f; };
  const float half_x = half_metres(row * std::abs(std::cos(yaw)) + 0.5f);
  const float half_z = half_metres(row * std::abs(std::sin(yaw)) + 0.5f);
  auto at = [&](float x, float z) { return pixel(r.scene_point({x, floor_y, z}, people) - panel); };
  const cv::Scalar grid(70, 70, 70);
  for (float x = -half_x; x <= half_x + 1e-3f; x += 0.5f)
    cv::line(right, at(x, -half_z), at(x, half_z), grid, 1, cv::LINE_AA);
  for (float z = -half_z; z <= half_z + 1e-3f; z += 0.5f)
    cv::line(right, at(-half_x, z), at(half_x, z), grid, 1, cv::LINE_AA);
}

// Slots left to right as the people's boxes stand in the 2D input; people without a box there
// after them, by id.
std::vector<const Person3D*> side_by_side_order(const People3D& people, const People2D& people2d) {
  std::map<int, float> box_centre;
  for (const Person2D& p : people2d.people) box_centre[p.id] = p.box.x + p.box.width / 2.0f;
  auto key = [&](const Person3D* p) {
    const auto it = box_centre.find(p->id);
    return it == box_centre.end() ? std::make_pair(1, float(p->id)) : std::make_pair(0, it->second);
  };
  std::vector<const Person3D*> order;
  for (const Person3D& p : people.people) order.push_back(&p);
  std::stable_sort(order.begin(), order.end(),
                   [&](const Person3D* a, const Person3D* b) { return key(a) < key(b); });
  return order;
}

void draw_people_3d(const OverlayRenderer& r, cv::Mat& right, const People3D& people,
                    const People2D& people2d) {
  const std::vector<const Person3D*> order = side_by_side_order(people, people2d);
  std::vector<Body3D> bodies;
  for (const Person3D* p : order) bodies.push_back(upright_positions(*p));
  const int count = std::max(1, static_cast<int>(order.size()));
  draw_floor(r, right, floor_height(bodies), count);
  const glm::vec2 panel(float(r.panel_width()), 0.0f);
  for (int slot = 0; slot < static_cast<int>(order.size()); ++slot) {
    const Body3D& body = bodies[static_cast<std::size_t>(slot)];
    auto project = [&](glm::vec3 p) { return r.right_point(p, slot, count) - panel; };
    const int id = order[static_cast<std::size_t>(slot)]->id;
    draw_skeleton(right, body, project, id_colour(id), 3);
    const glm::vec3 head = body[static_cast<std::size_t>(index(Joint::head))];
    if (finite(head))
      put_text(right, std::to_string(id), project(head) + glm::vec2(-6, -14), 0.5, id_colour(id));
  }
}

}  // namespace

std::array<glm::vec3, kBodyJoints> upright_positions(const Person3D& person) {
  const glm::vec3 image_up(0.0f, -1.0f, 0.0f);
  const glm::vec3 body_up = person.root.rotation * glm::vec3(0.0f, 1.0f, 0.0f);
  std::array<glm::vec3, kBodyJoints> out = person.positions;
  // No camera looks at the world upside down: such an "up" means the rotation was not set.
  if (!(glm::dot(body_up, image_up) > 0.0f)) return out;
  const glm::quat level = glm::rotation(glm::normalize(body_up), image_up);
  for (glm::vec3& p : out) p = level * p;
  return out;
}

Rgb id_colour(int id) {
  if (id < 0) return {200, 200, 200};
  // Golden angle: consecutive ids land far apart on the hue circle, for any number of ids.
  const double hue = std::fmod(static_cast<double>(id) * 137.50776405, 360.0);
  return from_hsv(static_cast<float>(hue), 0.8f, 0.95f);
}

OverlayRenderer::OverlayRenderer(const OverlayOptions& options) : options_(options) {
  for (int side : {options.canvas_width, options.canvas_height, options.panel_height}) {
    if (side < 16 || side > kMaxSide)
      throw std::invalid_argument("overlay: sizes must be 16 to 16384 pixels");
  }
  // Even sizes: video encoders work on 2x2 blocks.
  const double width = double(options.canvas_width) * options.panel_height / options.canvas_height;
  panel_width_ = std::clamp(2 * static_cast<int>(std::lround(width / 2.0)), 16, kMaxSide);
  options_.panel_height += options_.panel_height % 2;
}

glm::vec2 OverlayRenderer::left_point(glm::vec2 input, int input_width, int input_height) const {
  const float scale =
      std::min(float(panel_width_) / float(input_width), float(height()) / float(input_height));
  const glm::vec2 offset((float(panel_width_) - float(input_width) * scale) / 2.0f,
                         (float(height()) - float(input_height) * scale) / 2.0f);
  return offset + input * scale;
}

glm::vec2 OverlayRenderer::right_point(glm::vec3 point, int slot, int people) const {
  // Slots run along the view's horizontal axis on the floor, so the people stand side by side
  // on the screen, at one height, on the same floor.
  const float centred = float(slot) - float(people - 1) / 2.0f;
  const float yaw = glm::radians(options_.view_yaw_deg);
  const glm::vec3 along_screen(std::cos(yaw), 0.0f, std::sin(yaw));
  return scene_point(point + centred * options_.person_spacing_m * along_screen, people);
}

glm::vec2 OverlayRenderer::scene_point(glm::vec3 point, int people) const {
  // Turn about the vertical, then tilt to look down; orthographic, image y down as the input.
  const float yaw = glm::radians(options_.view_yaw_deg);
  const float pitch = glm::radians(options_.view_pitch_deg);
  const float x = std::cos(yaw) * point.x + std::sin(yaw) * point.z;
  const float z = -std::sin(yaw) * point.x + std::cos(yaw) * point.z;
  const float y = std::cos(pitch) * point.y - std::sin(pitch) * z;
  const float scene_width = std::max(4.0f, float(people) * options_.person_spacing_m + 1.0f);
  const float scale = std::min(float(panel_width_) / scene_width, float(height()) / 2.4f);
  return {float(panel_width_) * 1.5f + x * scale, float(height()) * 0.42f + y * scale};
}

ImageBuffer OverlayRenderer::render(const People2D& people2d, const People3D& people3d,
                                    const ImageBuffer& background,
                                    const OverlayLabel& label) const {
  ImageBuffer out(width(), height(), PixelFormat::bgr8);
  cv::Mat canvas = as_mat(out);
  canvas.setTo(cv::Scalar(24, 24, 24));
  const int input_width = background.empty() ? options_.canvas_width : background.width();
  const int input_height = background.empty() ? options_.canvas_height : background.height();
  const cv::Rect input_area(
      pixel(left_point({0, 0}, input_width, input_height)),
      pixel(left_point({float(input_width), float(input_height)}, input_width, input_height)));
  if (background.empty()) {
    canvas(input_area).setTo(cv::Scalar(48, 48, 48));
  } else {
    cv::Mat area = canvas(input_area);
    cv::resize(to_bgr(background), area, input_area.size(), 0, 0, cv::INTER_AREA);
  }
  cv::Mat left = canvas(cv::Rect(0, 0, panel_width_, height()));
  draw_people_2d(*this, left, people2d, input_width, input_height);
  cv::Mat right = canvas(cv::Rect(panel_width_, 0, panel_width_, height()));
  draw_people_3d(*this, right, people3d, people2d);
  put_text(canvas, frame_text(label), {10, 24}, 0.6, {255, 255, 255});
  put_text(canvas, "3D, second view", {float(panel_width_) + 10.0f, 24}, 0.6, {255, 255, 255});
  cv::line(canvas, {panel_width_, 0}, {panel_width_, height()}, cv::Scalar(90, 90, 90), 1);
  return out;
}

}  // namespace mocap::viz
