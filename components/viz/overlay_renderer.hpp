#pragma once
// The overlay picture: on the left the 2D input (keypoints, bones, box and id of every person, on
// the video frame or a blank canvas), on the right the reconstructed 3D skeletons seen from a
// second viewpoint (turned about the vertical and looking down, orthographic) over a floor grid,
// placed side by side since no root translation is estimated. Each person keeps one colour.
// Drawn with OpenCV, which stays inside the .cpp files of this library.

#include <array>
#include <cstdint>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/image_buffer.hpp"
#include "core/messages.hpp"

namespace mocap::viz {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb&) const = default;
};

// A stable colour per person id, well apart for neighbouring ids (golden-angle hues); light grey
// for untracked people (id < 0).
Rgb id_colour(int id);

// A person's joints turned so that their body stands up in the picture: a camera looking down
// (a high database view) sees a standing person tilted; the tilt is removed, the facing kept.
// The body's up is root.rotation * +Y (root.rotation: body frame, y up, to camera); positions
// are kept as they are when that rotation was not set (identity: "up" pointing down the image).
std::array<glm::vec3, kBodyJoints> upright_positions(const Person3D& person);

struct OverlayOptions {
  int canvas_width = 1920;  // the 2D input's pixel space when no video frame is given
  int canvas_height = 1080;
  int panel_height = 480;         // output height; each panel is scaled to it
  float view_yaw_deg = 35.0f;     // 3D panel: camera turned about the vertical from the input's
  float view_pitch_deg = 20.0f;   // ...and looking down by this much
  float person_spacing_m = 1.2f;  // 3D panel: distance between people placed side by side
};

// Text drawn in the corner.
struct OverlayLabel {
  std::int64_t frame = 0;
  double fps = 0.0;  // <= 0: not shown
};

class OverlayRenderer {
 public:
  // Throws std::invalid_argument for sizes below 16 pixels or above 16384.
  explicit OverlayRenderer(const OverlayOptions& options);

  // The output size, fixed for a run: two panels of panel_width() x height().
  int width() const { return 2 * panel_width_; }
  int height() const { return options_.panel_height; }
  int panel_width() const { return panel_width_; }

  // Draws one frame, BGR 8-bit. `background` is the video frame the 2D keypoints were found in
  // (any pixel format; its size then defines the 2D pixel space) or empty for a blank canvas.
  ImageBuffer render(const People2D& people2d, const People3D& people3d,
                     const ImageBuffer& background, const OverlayLabel& label) const;

  // Where a point of the 2D input's pixel space (of size `input_width` x `input_height`) lands
  // in the output: scaled to fit the left panel, centred.
  glm::vec2 left_point(glm::vec2 input, int input_width, int input_height) const;
  // Where a root-relative 3D point (metres, camera axes) of the person in slot `slot` of
  // `people` side-by-side slots lands in the output (right panel).
  glm::vec2 right_point(glm::vec3 point, int slot, int people) const;
  // The same for a point of the scene the people stand in (slot offsets already applied).
  glm::vec2 scene_point(glm::vec3 point, int people) const;
  float person_spacing_m() const { return options_.person_spacing_m; }
  float view_yaw_deg() const { return options_.view_yaw_deg; }

 private:
  OverlayOptions options_;
  int panel_width_ = 0;
};

}  // namespace mocap::viz
