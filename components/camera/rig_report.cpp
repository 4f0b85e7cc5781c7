#include "camera/rig_report.hpp"

#include <algorithm>
#include <array>
#include <iomanip>
#include <sstream>
#include <string_view>

namespace mocap::camera {
namespace {

constexpr std::array<std::string_view, 14> kCoefficients = {
    "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4", "tx", "ty"};

// Beyond this, the translations are hardly metres: anipose writes them in the board's unit.
constexpr double kImplausibleBaselineM = 100.0;

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::string vec3_text(const glm::dvec3& v, int digits) {
  return fixed(v.x, digits) + " " + fixed(v.y, digits) + " " + fixed(v.z, digits);
}

std::string padded(const std::string& text, std::size_t width) {
  return text.size() >= width ? text + " " : text + std::string(width - text.size(), ' ');
}

std::string right(const std::string& text, std::size_t width) {
  return text.size() >= width ? " " + text : std::string(width - text.size(), ' ') + text;
}

// A square table of one value per pair of cameras.
template <class Value>
void pair_table(std::ostringstream& out, const Rig& rig, std::size_t name_width, int digits,
                Value value) {
  const std::size_t width = std::max<std::size_t>(name_width, 9);
  out << padded("", name_width);
  for (const Camera& c : rig.cameras) out << right(c.name, width);
  out << "\n";
  for (const Camera& a : rig.cameras) {
    out << padded(a.name, name_width);
    for (const Camera& b : rig.cameras)
      out << right(&a == &b ? std::string("-") : fixed(value(a, b), digits), width);
    out << "\n";
  }
}

}  // namespace

std::string describe_distortion(const Camera& camera) {
  if (!camera.has_distortion()) return camera.fisheye ? "fisheye, none" : "none";
  std::string out = camera.fisheye ? "fisheye" : "";
  for (std::size_t i = 0; i < camera.distortion.size(); ++i) {
    if (!out.empty()) out += ' ';
    const std::string_view name =
        camera.fisheye ? kCoefficients[i < 2 ? i : i + 2] : kCoefficients[i];
    out += std::string(name) + " " + fixed(camera.distortion[i], 6);
  }
  return out;
}

std::string rig_report(const Rig& rig) {
  std::size_t name_width = 8;
  for (const Camera& c : rig.cameras) name_width = std::max(name_width, c.name.size() + 2);
  std::ostringstream out;
  out << rig.cameras.size() << (rig.cameras.size() == 1 ? " camera" : " cameras")
      << ", one world, metres (world -> camera: x_c = R x_w + t)\n\n";

  out << padded("camera", name_width) << padded("size", 12) << right("fx", 10) << right("fy", 10)
      << right("cx", 10) << right("cy", 10) << "  distortion\n";
  for (const Camera& c : rig.cameras) {
    out << padded(c.name, name_width)
        << padded(std::to_string(c.width) + "x" + std::to_string(c.height), 12)
        << right(fixed(c.fx, 2), 10) << right(fixed(c.fy, 2), 10) << right(fixed(c.cx, 2), 10)
        << right(fixed(c.cy, 2), 10) << "  " << describe_distortion(c) << "\n";
  }

  out << "\n"
      << padded("camera", name_width) << padded("position in the world (m)", 28)
      << padded("optical axis in the world", 28);
  if (rig.floor) out << right("height (m)", 11) << right("tilt (deg)", 11);
  out << "\n";
  for (const Camera& c : rig.cameras) {
    out << padded(c.name, name_width) << padded(vec3_text(c.centre(), 3), 28)
        << padded(vec3_text(c.optical_axis(), 3), 28);
    if (rig.floor)
      out << right(fixed(height_above_m(c, *rig.floor), 3), 11)
          << right(fixed(tilt_below_horizon_deg(c, *rig.floor), 1), 11);
    out << "\n";
  }
  if (rig.floor)
    out << "(height: of the camera centre above the floor; tilt: of the optical axis below the "
           "horizon)\n";

  if (rig.cameras.size() > 1) {
    out << "\nbaselines: distance between camera centres (m)\n";
    pair_table(out, rig, name_width, 3, baseline_m);
    out << "\nangles between optical axes (deg)\n";
    pair_table(out, rig, name_width, 1, axis_angle_deg);
    double widest = 0.0;
    for (const Camera& a : rig.cameras)
      for (const Camera& b : rig.cameras) widest = std::max(widest, baseline_m(a, b));
    if (widest > kImplausibleBaselineM)
      out << "\nwarning: cameras up to " << fixed(widest, 0)
          << " m apart: are the translations in millimetres? (anipose writes them in the unit of "
             "its board's square size; a rig file is in metres)\n";
  }

  out << "\nfloor: ";
  if (rig.floor) {
    out << "dot(normal, x) + offset = 0 with normal " << vec3_text(rig.floor->normal, 4)
        << " (up), offset " << fixed(rig.floor->offset, 4) << " m (world frame)\n";
  } else {
    out << "not given\n";
  }
  return out.str();
}

}  // namespace mocap::camera
