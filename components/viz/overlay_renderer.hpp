#pragma once
// The overlay picture: on the left the 2D input (keypoints, bones, box and id of every person, on
// the video frame or a blank canvas), on the right the reconstructed 3D skeletons in the scene,
// seen from a second viewpoint (viz/scene_view.hpp): placed where the fitting put them
// (Person3D::placed, the root translation) on the frame's floor, with a floor grid and the real
// camera's position; people without a translation stand in a row in front of the camera. A
// virtual camera (turned about the vertical, looking down, orthographic) frames them all and
// follows them from frame to frame. Each person keeps one colour. Drawn with OpenCV, which stays
// inside the .cpp files of this library.

#include <array>
#include <cstdint>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/image_buffer.hpp"
#include "core/messages.hpp"
#include "viz/scene_view.hpp"

namespace mocap::viz {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb&) const = default;
};

// A stable colour per person id, well apart for neighbouring ids (golden-angle hues); light grey
// for untracked people (id < 0).
Rgb id_colour(int id);

struct OverlayOptions {
  int canvas_width = 1920;  // the 2D input's pixel space when no video frame is given
  int canvas_height = 1080;
  int panel_height = 480;         // output height; each panel is scaled to it
  float view_yaw_deg = 35.0f;     // 3D panel: camera turned about the vertical from the input's
  float view_pitch_deg = 30.0f;   // ...and looking down by this much
  float person_spacing_m = 1.2f;  // 3D panel: distance between unplaced people in their row
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
  // Frames are drawn in order: the 3D view follows the people from one to the next.
  ImageBuffer render(const People2D& people2d, const People3D& people3d,
                     const ImageBuffer& background, const OverlayLabel& label);

  // Where a point of the 2D input's pixel space (of size `input_width` x `input_height`) lands
  // in the output: scaled to fit the left panel, centred.
  glm::vec2 left_point(glm::vec2 input, int input_width, int input_height) const;
  // Where a point of the scene (camera frame, metres; a ScenePerson's joint) landed in the output
  // (right panel) in the frame drawn last.
  glm::vec2 scene_pixel(glm::vec3 camera_point) const;
  const SceneCamera& scene_camera() const { return camera_; }

 private:
  OverlayOptions options_;
  int panel_width_ = 0;
  SceneCamera camera_;
};

}  // namespace mocap::viz
