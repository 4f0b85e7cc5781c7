#include "viz/overlay_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "viz/image_convert.hpp"

namespace mocap::viz {
namespace {

constexpr int kMaxSide = 16384;
constexpr int kTitleHeight = 32;  // pixels at the top of the 3D panel kept for its title

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

// Grid lines on the floor every `step` metres, the step the smallest of 0.5, 1, 2, 5, 10 m that
// leaves 24 pixels between lines, over the floor the panel shows; fixed to the floor, so the grid
// moves with the view, not with the people.
void draw_floor(cv::Mat& right, const SceneCamera& camera) {
  float step = 10.0f;
  for (float s : {0.5f, 1.0f, 2.0f, 5.0f}) {
    if (s * camera.pixels_per_metre() >= 24.0f) {
      step = s;
      break;
    }
  }
  const auto [x0, a0, x1, a1] = camera.visible_floor(step);
  const cv::Scalar grid(56, 56, 56);
  auto at = [&](float x, float ahead) { return pixel(camera.project_floor({x, 0.0f, ahead})); };
  for (float x = x0; x <= x1 + 1e-3f; x += step)
    cv::line(right, at(x, a0), at(x, a1), grid, 1, cv::LINE_AA);
  for (float a = a0; a <= a1 + 1e-3f; a += step)
    cv::line(right, at(x0, a), at(x1, a), grid, 1, cv::LINE_AA);
}

// The real camera: a dot at its centre over a line down to the floor, when the view shows it.
void draw_camera(cv::Mat& right, const SceneCamera& camera) {
  const glm::vec2 centre = camera.project(glm::vec3(0.0f));
  const glm::vec3 below = camera.floor_coordinates(glm::vec3(0.0f)) * glm::vec3(1, 0, 1);
  const cv::Rect panel(0, 0, right.cols, right.rows);
  if (!panel.contains(pixel(centre))) return;
  cv::line(right, pixel(centre), pixel(camera.project_floor(below)), cv::Scalar(150, 150, 150), 1,
           cv::LINE_AA);
  cv::circle(right, pixel(centre), 4, cv::Scalar(230, 230, 230), -1, cv::LINE_AA);
  put_text(right, "camera", centre + glm::vec2(6, -6), 0.4, {200, 200, 200});
}

// The people where they stand (scene_view.hpp), the farthest first so nearer ones cover them.
void draw_people_3d(cv::Mat& right, SceneCamera& camera, const People3D& people3d,
                    const People2D& people2d, float spacing_m) {
  const GroundPlane floor = scene_floor(people3d);
  std::vector<ScenePerson> people = scene_people(people3d, people2d, floor, spacing_m);
  camera.follow(floor, people);
  draw_floor(right, camera);
  draw_camera(right, camera);
  const auto root = static_cast<std::size_t>(index(Joint::root));
  std::stable_sort(people.begin(), people.end(), [&](const ScenePerson& a, const ScenePerson& b) {
    return camera.depth(a.joints[root]) > camera.depth(b.joints[root]);
  });
  const int thickness = std::clamp(static_cast<int>(camera.pixels_per_metre() / 40.0f), 2, 3);
  auto project = [&](glm::vec3 p) { return camera.project(p); };
  for (const ScenePerson& p : people) {
    draw_skeleton(right, p.joints, project, id_colour(p.id), thickness);
    const glm::vec3 head = p.joints[static_cast<std::size_t>(index(Joint::head))];
    if (finite(head))
      put_text(right, std::to_string(p.id), project(head) + glm::vec2(-6, -12), 0.5,
               id_colour(p.id));
  }
}

std::string scene_title(const People3D& people) {
  std::size_t unplaced = 0;
  for (const Person3D& p : people.people) unplaced += p.placed ? 0 : 1;
  if (unplaced == 0) return "3D, second view";
  return "3D, second view (" + std::to_string(unplaced) + " not placed: in a row)";
}

// Even sizes: video encoders work on 2x2 blocks.
int even(double pixels) {
  return std::clamp(2 * static_cast<int>(std::lround(pixels / 2.0)), 16, kMaxSide);
}

const OverlayOptions& checked(const OverlayOptions& options) {
  for (int side : {options.canvas_width, options.canvas_height, options.panel_height}) {
    if (side < 16 || side > kMaxSide)
      throw std::invalid_argument("overlay: sizes must be 16 to 16384 pixels");
  }
  return options;
}

}  // namespace

Rgb id_colour(int id) {
  if (id < 0) return {200, 200, 200};
  // Golden angle: consecutive ids land far apart on the hue circle, for any number of ids.
  const double hue = std::fmod(static_cast<double>(id) * 137.50776405, 360.0);
  return from_hsv(static_cast<float>(hue), 0.8f, 0.95f);
}

OverlayRenderer::OverlayRenderer(const OverlayOptions& options)
    : options_(checked(options)),
      panel_width_(
          even(double(options.canvas_width) * options.panel_height / options.canvas_height)),
      camera_(panel_width_, options.panel_height + options.panel_height % 2, kTitleHeight,
              options.view_yaw_deg, options.view_pitch_deg) {
  options_.panel_height += options_.panel_height % 2;
}

glm::vec2 OverlayRenderer::left_point(glm::vec2 input, int input_width, int input_height) const {
  const float scale =
      std::min(float(panel_width_) / float(input_width), float(height()) / float(input_height));
  const glm::vec2 offset((float(panel_width_) - float(input_width) * scale) / 2.0f,
                         (float(height()) - float(input_height) * scale) / 2.0f);
  return offset + input * scale;
}

glm::vec2 OverlayRenderer::scene_pixel(glm::vec3 camera_point) const {
  return camera_.project(camera_point) + glm::vec2(float(panel_width_), 0.0f);
}

ImageBuffer OverlayRenderer::render(const People2D& people2d, const People3D& people3d,
                                    const ImageBuffer& background, const OverlayLabel& label) {
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
  draw_people_3d(right, camera_, people3d, people2d, options_.person_spacing_m);
  put_text(canvas, frame_text(label), {10, 24}, 0.6, {255, 255, 255});
  put_text(canvas, scene_title(people3d), {float(panel_width_) + 10.0f, 24}, 0.6, {255, 255, 255});
  cv::line(canvas, {panel_width_, 0}, {panel_width_, height()}, cv::Scalar(90, 90, 90), 1);
  return out;
}

}  // namespace mocap::viz
