#pragma once
// A virtual capture room for rig calibration tests and the benchmark: N cameras on a ring around
// the room looking at its centre, a ChArUco board moved through the space (frame 0: lying flat on
// the floor at the world origin), every view rendered with support/board_render.hpp (blur and
// noise) into one folder of PNGs per camera. World: z up, floor z = 0, metres; the floor board's
// frame is the world as `mocap calibrate rig` defines it (x along the board, z up). With
// `floor_frames` > 1 the board lies on the floor again after the frames in the air, slid to other
// spots and turned, as a user filming several floor frames would (floor_frame_indices()).

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "camera/board.hpp"
#include "camera/camera.hpp"
#include "support/board_render.hpp"

namespace mocap::test {

struct VirtualRoom {
  int cameras = 4;
  int frames = 12;  // frame 0 is the board on the floor
  // Frames of the board lying on the floor: frame 0, then floor_frames - 1 more after the
  // `frames` frames (so the frames before are the same with any value), the board's centre
  // floor_spot_radius_m from the room's centre at evenly spread directions (a random start) and
  // turned at random about the vertical. From a generator of their own.
  int floor_frames = 1;
  double floor_spot_radius_m = 0.8;
  int width = 640, height = 360;
  double hfov_deg = 70.0;
  double ring_radius_m = 2.2;  // cameras stand 2.0 .. 2.6 m from the centre (a 4 m room)
  unsigned seed = 1;
  // Each camera's principal point off the image centre by up to this much (px, uniform in x and
  // y, from a generator of its own: the scene is the same with any value); 0: centred.
  double principal_offset_px = 0.0;
  camera::BoardSpec board{camera::BoardKind::charuco, 6, 4, 150.0, 110.0, "DICT_4X4_50"};
};

struct BoardPlacement {
  glm::dmat3 rotation{1.0};  // board -> world
  glm::dvec3 origin{0.0};    // board origin in the world, metres
};

struct VirtualRig {
  std::vector<camera::Camera> cameras;  // the truth
  std::vector<BoardPlacement> boards;   // per frame
  std::vector<std::vector<bool>> seen;  // [camera][frame]: the board was rendered in view
};

// The frames in which the board lies on the floor: 0, then those after room.frames.
inline std::vector<int> floor_frame_indices(const VirtualRoom& room) {
  std::vector<int> out{0};
  for (int j = 1; j < room.floor_frames; ++j) out.push_back(room.frames + j - 1);
  return out;
}

inline glm::dmat3 look_at(const glm::dvec3& from, const glm::dvec3& to) {
  const glm::dvec3 z = glm::normalize(to - from);
  const glm::dvec3 x = glm::normalize(glm::cross(z, glm::dvec3(0, 0, 1)));
  return glm::dmat3(x, glm::cross(z, x), z);  // columns: camera x right, y down, z forward
}

inline VirtualRig make_virtual_rig(const VirtualRoom& room) {
  std::mt19937 rng(room.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  VirtualRig rig;
  std::mt19937 offset_rng(room.seed + 1);
  const double pi = std::acos(-1.0);
  for (int k = 0; k < room.cameras; ++k) {
    const double angle = 2 * pi * k / room.cameras + 0.15 * unit(rng);
    const double radius = room.ring_radius_m + 0.3 * unit(rng);
    const double height = 2.0 + 0.5 * unit(rng);
    const glm::dvec3 centre(radius * std::cos(angle), radius * std::sin(angle), height);
    const glm::dvec3 target(0.3 * unit(rng), 0.3 * unit(rng), 0.8 + 0.2 * unit(rng));
    camera::Camera c =
        camera::Camera::from_fov(room.width, room.height, room.hfov_deg,
                                 "cam_" + std::string(k < 9 ? "0" : "") + std::to_string(k + 1));
    c.set_pose_from_centre(look_at(centre, target), centre);
    c.cx += room.principal_offset_px * unit(offset_rng);
    c.cy += room.principal_offset_px * unit(offset_rng);
    rig.cameras.push_back(c);
  }
  const double w = room.board.columns * room.board.square_mm / 1000.0;
  const double h = room.board.rows * room.board.square_mm / 1000.0;
  // Frame 0: face up on the floor, its frame the world's with y and z turned (x along, z up).
  rig.boards.push_back({glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1)),
                        glm::dvec3(0.0)});
  for (int f = 1; f < room.frames; ++f) {
    // Facing a direction between the cameras, tilted and rolled, somewhere in the middle of the
    // room: two or three cameras see it, sometimes one.
    const double facing = 2 * pi * (f + 0.5 * unit(rng)) / 5.0;
    const double pitch = 0.5 * unit(rng);
    const glm::dvec3 front(std::cos(facing) * std::cos(pitch), std::sin(facing) * std::cos(pitch),
                           std::sin(pitch));
    const glm::dvec3 z = -front;  // the board's z points into it
    glm::dvec3 x = glm::normalize(glm::cross(glm::dvec3(0, 0, 1), front));
    const double roll = 0.5 * unit(rng);
    x = std::cos(roll) * x + std::sin(roll) * glm::cross(z, x);
    const glm::dvec3 y = glm::cross(z, x);
    const glm::dvec3 centre(0.6 * unit(rng), 0.6 * unit(rng), 1.0 + 0.5 * unit(rng));
    const glm::dmat3 rotation(x, y, z);
    rig.boards.push_back({rotation, centre - rotation * glm::dvec3(w / 2, h / 2, 0)});
  }
  std::mt19937 floor_rng(room.seed + 2);
  std::uniform_real_distribution<double> turn(0.0, 2 * pi);
  const double start = turn(floor_rng);
  for (int j = 1; j < room.floor_frames; ++j) {
    // Face up (z into the floor), turned by `yaw` about the vertical.
    const double direction = start + 2 * pi * (j - 1) / (room.floor_frames - 1);
    const double yaw = turn(floor_rng);
    const glm::dvec3 x(std::cos(yaw), std::sin(yaw), 0.0);
    const glm::dvec3 z(0, 0, -1);
    const glm::dmat3 rotation(x, glm::cross(z, x), z);
    const glm::dvec3 centre(room.floor_spot_radius_m * std::cos(direction),
                            room.floor_spot_radius_m * std::sin(direction), 0.0);
    rig.boards.push_back({rotation, centre - rotation * glm::dvec3(w / 2, h / 2, 0)});
  }
  return rig;
}

// Renders every view into `folder`/<camera>/frame_NNN.png; returns the camera folders.
inline std::vector<std::string> render_virtual_rig(VirtualRig& rig, const VirtualRoom& room,
                                                   const std::filesystem::path& folder) {
  const CharucoTexture texture =
      charuco_texture(room.board.columns, room.board.rows, room.board.square_mm,
                      room.board.marker_mm, cv::aruco::DICT_4X4_50, 80);
  const double w = room.board.columns * room.board.square_mm / 1000.0;
  const double h = room.board.rows * room.board.square_mm / 1000.0;
  std::vector<std::string> folders;
  rig.seen.assign(rig.cameras.size(), std::vector<bool>(rig.boards.size(), false));
  for (std::size_t k = 0; k < rig.cameras.size(); ++k) {
    const camera::Camera& c = rig.cameras[k];
    const std::filesystem::path dir = folder / c.name;
    std::filesystem::create_directories(dir);
    folders.push_back(dir.string());
    const cv::Matx33d K(c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
    for (std::size_t f = 0; f < rig.boards.size(); ++f) {
      const BoardPlacement& b = rig.boards[f];
      const glm::dmat3 R = c.rotation * b.rotation;
      const glm::dvec3 t = c.to_camera(b.origin);
      // Its printed face toward the camera, at most 75 degrees off.
      const glm::dvec3 to_camera =
          glm::normalize(c.centre() - (b.origin + b.rotation * glm::dvec3(w / 2, h / 2, 0)));
      bool visible = glm::dot(-b.rotation[2], to_camera) > std::cos(75.0 * std::acos(-1.0) / 180);
      for (double u : {0.0, w})
        for (double v : {0.0, h}) {
          const glm::dvec3 corner = R * glm::dvec3(u, v, 0) + t;
          const glm::dvec2 pixel = c.project_pinhole(b.origin + b.rotation * glm::dvec3(u, v, 0));
          visible = visible && corner.z > 0.3 && pixel.x > -0.2 * c.width &&
                    pixel.x < 1.2 * c.width && pixel.y > -0.2 * c.height &&
                    pixel.y < 1.2 * c.height;
        }
      cv::Mat image;
      const unsigned seed = room.seed * 7919u + static_cast<unsigned>(k * 1000 + f);
      if (visible) {
        cv::Matx33d Rcv;
        for (int r = 0; r < 3; ++r)
          for (int col = 0; col < 3; ++col) Rcv(r, col) = R[col][r];
        cv::Vec3d rvec;
        cv::Rodrigues(Rcv, rvec);
        image = render_board(texture, K, cv::Size(c.width, c.height), rvec,
                             cv::Vec3d(t.x, t.y, t.z) * 1000.0, seed);
        rig.seen[k][f] = true;
      } else {
        // Out of view or facing away: the empty room.
        image = cv::Mat(c.height, c.width, CV_8U, cv::Scalar(110));
        cv::Mat noise(image.size(), CV_8S);
        cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0.0, 2.0);
        cv::add(image, noise, image, cv::noArray(), CV_8U);
      }
      char name[32];
      std::snprintf(name, sizeof name, "frame_%03zu.png", f);
      cv::imwrite((dir / name).string(), image);
    }
  }
  return folders;
}

}  // namespace mocap::test
