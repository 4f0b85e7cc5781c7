// mocap-bench-rig-board: `mocap calibrate rig` (camera/rig_calibration.hpp) on SYNTHETIC renders
// of a ChArUco board in a 4 m room seen by a ring of virtual cameras
// (tests/support/virtual_rig.hpp: blur and noise, frame 0 the board flat on the floor). Prints, per
// camera, the position (mm) and angle (degrees) errors against the truth, the RMS reprojection
// error, the corners found against their true pixels; then the same after the best rigid alignment
// to the truth (what the bundle adjustment got wrong, without the floor board's pose), the
// principal point's error, and each camera's angle once the rotation common to all (the floor
// board's) is taken out; for intrinsics given, held, refined with p1 p2 fitted and refined with p1
// p2 held. Then a camera that shares no frame. --principal-offset moves the virtual cameras'
// principal points off the image centre (the estimate starts at the centre only in the bundle's
// first guess from cv::calibrateCamera, which fits it).
//
// The error decomposed: each camera's position error is the rigid motion that best maps the
// estimated centres onto the true ones (the world: how the floor board(s) placed and turned it;
// its tilt, the floor normal's error, and the origin's shift are printed per run) plus what is left
// (the rig's shape: relative poses, focal lengths), and the similarity alignment's scale.
// --floor-frames N renders N - 1 more frames of the board lying on the floor, after the others
// (virtual_rig.hpp); "before" calibrates the first --frames frames with the one floor frame (the
// same renders as without them), "after" all frames with the world from every floor frame.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "camera/rig_calibration.hpp"
#include "cli_args.hpp"
#include "core/input_error.hpp"
#include "support/files.hpp"
#include "support/virtual_rig.hpp"

namespace {

using namespace mocap;
using namespace mocap::camera;

double rotation_error_deg(const glm::dmat3& a, const glm::dmat3& b) {
  const glm::dmat3 d = a * glm::transpose(b);
  const double trace = d[0][0] + d[1][1] + d[2][2];
  return std::acos(std::clamp((trace - 1) / 2, -1.0, 1.0)) * 180.0 / std::acos(-1.0);
}

// How far the corners found lie from the truth's projection of their board points (px, RMS).
double corner_error_px(const CameraBoardViews& view, const Camera& truth,
                       const test::VirtualRig& rig) {
  double squared = 0;
  long n = 0;
  for (std::size_t f = 0; f < view.boards.size(); ++f) {
    if (!view.boards[f]) continue;
    const auto& b = *view.boards[f];
    for (std::size_t i = 0; i < b.pixels.size(); ++i) {
      const glm::dvec3 local(b.object_mm[i][0] / 1000, b.object_mm[i][1] / 1000, 0);
      const glm::dvec2 p = truth.project(rig.boards[f].origin + rig.boards[f].rotation * local);
      squared += std::pow(p.x - b.pixels[i][0], 2) + std::pow(p.y - b.pixels[i][1], 2);
      ++n;
    }
  }
  return n ? std::sqrt(squared / static_cast<double>(n)) : 0.0;
}

// The similarity (rotation, translation, scale) that best maps the estimated centres onto the
// truth's (Umeyama); its rotation and translation are the rigid part (the scale is not applied).
struct Alignment {
  cv::Matx33d R = cv::Matx33d::eye();
  cv::Vec3d t;
  double scale = 1.0;
};

Alignment similarity(const std::vector<glm::dvec3>& got, const std::vector<glm::dvec3>& want) {
  glm::dvec3 mg(0.0), mw(0.0);
  for (std::size_t i = 0; i < got.size(); ++i) mg += got[i], mw += want[i];
  mg /= static_cast<double>(got.size());
  mw /= static_cast<double>(got.size());
  cv::Matx33d cov = cv::Matx33d::zeros();
  double spread = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    const glm::dvec3 a = got[i] - mg, b = want[i] - mw;
    spread += glm::dot(a, a);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) cov(r, c) += b[r] * a[c];
  }
  cv::Mat w, u, vt;
  cv::SVD::compute(cv::Mat(cov), w, u, vt);
  cv::Mat d = cv::Mat::eye(3, 3, CV_64F);
  if (cv::determinant(u * vt) < 0) d.at<double>(2, 2) = -1;
  Alignment out;
  out.R = cv::Matx33d(cv::Mat(u * d * vt));
  out.scale = cv::sum(cv::Mat(w.t() * d.diag()))[0] / spread;
  const cv::Vec3d g(mg.x, mg.y, mg.z), m(mw.x, mw.y, mw.z);
  out.t = m - out.R * g;  // rigid: the scale is reported, not applied
  return out;
}

struct Worst {
  double max_mm = 0, max_deg = 0;
};

// How the intrinsics are had: given (the truth), or from each camera's own frames, held as
// calibrated or refined in the bundle, p1 p2 fitted or held at zero, fx and fy apart or one
// (before 2026-11-26 the command's only way was p1 p2 fitted, fx and fy apart); and where the
// world comes from: the one floor frame 0 on the first --frames frames (before), or every floor
// frame on all frames.
struct Mode {
  const char* what;
  bool given, refine, tangential, square;
  bool all_floor_frames = false;  // all frames, the world from every floor frame
  bool all_frames = false;        // all frames (the extra floor frames too), the world from frame 0
  int outlier_rounds = 2;
};
// The intrinsics models compared on 2026-11-26 (--models).
constexpr Mode kModels[] = {
    {"given (the truth)", true, false, false, false},
    {"from each camera's own frames, held (p1 p2 fitted, fx fy apart)", false, false, true, false},
    {"from each camera's own frames, refined in the bundle, p1 p2 fitted, fx fy apart", false, true,
     true, false},
    {"from each camera's own frames, refined in the bundle, p1 p2 held at 0, fx fy apart", false,
     true, false, false},
    {"from each camera's own frames, refined in the bundle, p1 p2 held at 0, fx = fy (the "
     "default)",
     false, true, false, true},
};
// The world from one floor frame against several (issue 20, rig-floor).
constexpr Mode kFloorModes[] = {
    {"given (the truth); floor frame 0 (before)", true, false, false, false},
    {"the default (own frames, refined, p1 p2 held, fx = fy); floor frame 0 (before)", false, true,
     false, true},
    {"the default; floor frame 0; no outlier rounds", false, true, false, true, false, false, 0},
    {"the default; all frames, the extra floor frames as ordinary ones, the world from frame 0",
     false, true, false, true, false, true},
    {"given (the truth); the world from every floor frame (after)", true, false, false, false,
     true},
    {"the default; the world from every floor frame (after)", false, true, false, true, true},
};

struct Scene {
  test::VirtualRig truth;
  std::vector<CameraBoardViews> views;  // every frame
  int frames = 0;                       // --frames: the frames before the extra floor frames
  std::vector<int> floor_frames;        // with the board found in a camera
};

void report(const Scene& scene, const Mode& mode, const RigBoardOptions& search);

// One scene, rendered and searched once, calibrated each way.
void run(int cameras, int frames, int width, int height, unsigned seed, double offset,
         int floor_frames, bool models, bool quick) {
  test::VirtualRoom room;
  room.cameras = cameras;
  room.frames = frames;
  room.width = width;
  room.height = height;
  room.seed = seed;
  room.principal_offset_px = offset;
  room.floor_frames = floor_frames;
  room.board = {BoardKind::charuco, 7, 5, 100.0, 75.0, "DICT_4X4_50"};
  Scene scene;
  scene.truth = test::make_virtual_rig(room);
  scene.frames = frames;
  test::TempDir dir;
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<std::string> folders = test::render_virtual_rig(scene.truth, room, dir.path());
  const auto t1 = std::chrono::steady_clock::now();
  RigBoardOptions search;
  search.board = room.board;
  std::vector<std::string> names;
  for (const Camera& c : scene.truth.cameras) names.push_back(c.name);
  scene.views = find_rig_board(folders, names, search);
  const auto t2 = std::chrono::steady_clock::now();
  const auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::printf(
      "\n## %d cameras, %d frames, %dx%d px (seed %u): render %.1f s, find the board %.1f s\n",
      cameras, frames, width, height, seed, seconds(t0, t1), seconds(t1, t2));
  // The floor frames a camera found the board in (a user lists those; the others are refused).
  std::printf("\nfloor frames:");
  for (int f : test::floor_frame_indices(room)) {
    int found = 0;
    for (const auto& v : scene.views) found += v.boards[static_cast<std::size_t>(f)].has_value();
    std::printf(" %d (%d cameras)", f, found);
    if (found > 0) scene.floor_frames.push_back(f);
  }
  std::printf("\n");
  if (models || quick) {
    for (const Mode& mode : kModels) {
      report(scene, mode, search);
      if (quick) break;
    }
    return;
  }
  for (const Mode& mode : kFloorModes)
    if (floor_frames > 1 || (!mode.all_floor_frames && !mode.all_frames))
      report(scene, mode, search);
}

// The views cut to their first `frames` frames.
std::vector<CameraBoardViews> first_frames(std::vector<CameraBoardViews> views, int frames) {
  for (CameraBoardViews& v : views) {
    v.boards.resize(static_cast<std::size_t>(frames));
    v.frames = frames;
  }
  return views;
}

void report(const Scene& scene, const Mode& mode, const RigBoardOptions& search) {
  const test::VirtualRig& truth = scene.truth;
  RigBoardOptions options = search;
  options.refine_intrinsics = mode.refine;
  options.tangential_distortion = mode.tangential;
  options.square_pixels = mode.square;
  options.outlier_rounds = mode.outlier_rounds;
  if (mode.given) options.intrinsics = Rig{truth.cameras, std::nullopt};
  if (mode.all_floor_frames) options.floor_frames = scene.floor_frames;
  const bool all = mode.all_floor_frames || mode.all_frames;
  const std::vector<CameraBoardViews> views =
      all ? scene.views : first_frames(scene.views, scene.frames);
  const auto t2 = std::chrono::steady_clock::now();
  const RigCalibration result = calibrate_rig(views, options);
  const auto t3 = std::chrono::steady_clock::now();
  const double seconds = std::chrono::duration<double>(t3 - t2).count();

  std::printf("\n### intrinsics %s\n\n", mode.what);
  std::printf("calibrate %.2f s; %d frames with the board, floor frames", seconds,
              result.frames_used);
  for (const FloorFrameReport& f : result.floor_frames)
    std::printf(" %d (%d corners, %.1f mm off the plane, tilted %.3f deg)", f.frame, f.corners,
                f.max_off_mm, f.tilt_deg);
  std::printf("; RMS %.3f px\n", result.rms_px);
  for (const std::string& note : result.notes) std::printf("note: %s\n", note.c_str());
  std::vector<glm::dvec3> got, want;
  for (std::size_t k = 0; k < result.rig.cameras.size(); ++k) {
    got.push_back(result.rig.cameras[k].centre());
    want.push_back(truth.cameras[k].centre());
  }
  // The world's error: the rigid motion estimated world -> true world.
  const Alignment align = similarity(got, want);
  const cv::Vec3d up = align.R * cv::Vec3d(0, 0, 1);
  const double tilt = std::acos(std::clamp(up[2], -1.0, 1.0)) * 180.0 / std::acos(-1.0);
  const cv::Vec3d x = align.R * cv::Vec3d(1, 0, 0);
  const double yaw = std::atan2(x[1], x[0]) * 180.0 / std::acos(-1.0);
  std::printf(
      "world (the rigid motion onto the truth): floor normal off by %.4f deg, turned %.4f deg "
      "about the vertical, origin off by %.2f mm (%.2f %.2f %.2f); scale %+.4f %%\n\n",
      tilt, yaw, 1000 * cv::norm(align.t), 1000 * align.t[0], 1000 * align.t[1], 1000 * align.t[2],
      100 * (align.scale - 1));
  std::printf(
      "| camera | frames with board (shown) | corners used | dropped | RMS px | corners vs "
      "truth px | position mm | angle deg | world part mm | shape part (after rigid alignment) mm "
      "| fx error %% | cx err px | cy err px | angle after common rotation deg "
      "|\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  // The common rotation (estimated world -> true world) from the camera -> world rotations.
  cv::Matx33d sum = cv::Matx33d::zeros();
  for (std::size_t k = 0; k < result.rig.cameras.size(); ++k) {
    const glm::dmat3 m = glm::transpose(truth.cameras[k].rotation) * result.rig.cameras[k].rotation;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) sum(r, c) += m[c][r];
  }
  cv::Mat sw, su, svt;
  cv::SVD::compute(cv::Mat(sum), sw, su, svt);
  const cv::Matx33d G(cv::Mat(su * svt));
  glm::dmat3 g;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) g[c][r] = G(r, c);
  double worst_common = 0, worst_world = 0, worst_shape = 0;
  Worst row;
  for (std::size_t k = 0; k < result.rig.cameras.size(); ++k) {
    const Camera& c = result.rig.cameras[k];
    const Camera& t = truth.cameras[k];
    int shown = 0;
    for (std::size_t f = 0; f < views[k].boards.size(); ++f) shown += truth.seen[k][f];
    const double mm = 1000 * glm::length(c.centre() - t.centre());
    const double deg = rotation_error_deg(c.rotation, t.rotation);
    const cv::Vec3d moved = align.R * cv::Vec3d(got[k].x, got[k].y, got[k].z) + align.t;
    const glm::dvec3 aligned(moved[0], moved[1], moved[2]);
    const double world_mm = 1000 * glm::length(aligned - got[k]);
    const double shape_mm = 1000 * glm::length(aligned - t.centre());
    row.max_mm = std::max(row.max_mm, mm);
    row.max_deg = std::max(row.max_deg, deg);
    worst_world = std::max(worst_world, world_mm);
    worst_shape = std::max(worst_shape, shape_mm);
    const auto& r = result.cameras[k];
    const double common = rotation_error_deg(c.rotation * glm::transpose(g), t.rotation);
    worst_common = std::max(worst_common, common);
    std::printf(
        "| %s | %d (%d) | %d | %d | %.3f | %.3f | %.2f | %.3f | %.2f | %.2f | %.3f | %.2f | %.2f "
        "| %.3f |\n",
        c.name.c_str(), r.frames_with_board, shown, r.observations, r.dropped, r.rms_px,
        corner_error_px(views[k], t, truth), mm, deg, world_mm, shape_mm,
        100 * (c.fx - t.fx) / t.fx, c.cx - t.cx, c.cy - t.cy, common);
  }
  std::printf("| **worst** | | | | | | **%.2f** | **%.3f** | %.2f | %.2f | | | | %.3f |\n",
              row.max_mm, row.max_deg, worst_world, worst_shape, worst_common);
  int dropped = 0, used = 0;
  for (const auto& r : result.cameras) dropped += r.dropped, used += r.observations;
  std::printf(
      "\nsummary | %s | worst position %.2f mm | worst angle %.3f deg | world part %.2f mm | "
      "shape part %.2f mm | floor normal %.4f deg | origin %.2f mm | scale %+.4f %% | RMS %.3f px "
      "| dropped %d of %d |\n",
      mode.what, row.max_mm, row.max_deg, worst_world, worst_shape, tilt, 1000 * cv::norm(align.t),
      100 * (align.scale - 1), result.rms_px, dropped, dropped + used);

  if (mode.given && !all) {
    // The last camera loses the frames it shares and sees the board alone in one more frame.
    std::vector<CameraBoardViews> cut = views;
    auto& last = cut.back();
    for (std::size_t f = 0; f < last.boards.size(); ++f)
      for (std::size_t k = 0; k + 1 < cut.size(); ++k)
        if (cut[k].boards[f]) last.boards[f].reset();
    for (auto& v : cut) v.boards.emplace_back();
    for (const auto& b : views.back().boards)
      if (b) last.boards.back() = b;
    try {
      calibrate_rig(cut, options);
      std::printf("\na camera sharing no frame: ACCEPTED (wrong)\n");
    } catch (const InputError& e) {
      std::printf(
          "\na camera sharing no frame (%s loses the frames it shares and sees the board "
          "alone in one more frame): refused: %s\n",
          last.name.c_str(), e.what());
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  mocap::cli::Args args(
      "mocap-bench-rig-board [--frames N] [--width PX] [--height PX] [--seed N] [--cameras N] "
      "[--principal-offset PX] [--floor-frames N] [--models] [--quick]",
      "Board calibration of a virtual rig against the truth (synthetic "
      "renders; docs/cameras.md).");
  args.option("frames", "N", "frames per run (frame 0: the board on the floor)", "60")
      .option("width", "PX", "image width", "1280")
      .option("height", "PX", "image height", "720")
      .option("seed", "N", "scene seed", "1")
      .option("principal-offset", "PX",
              "each camera's principal point up to PX off the image centre (0: centred)", "0")
      .option("cameras", "N", "only the rig of N cameras (0: the 4- and 8-camera rigs)", "0")
      .option("floor-frames", "N",
              "frames of the board on the floor: frame 0 and N - 1 more after the others; the "
              "world from frame 0 (before) against from all of them (after)",
              "4")
      .flag("models", "the intrinsics models compared on 2026-11-26 instead (floor frame 0)")
      .flag("quick", "only the 4-camera run with given intrinsics");
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // tables as they come, also into a file
  const int frames = static_cast<int>(args.integer("frames"));
  const int width = static_cast<int>(args.integer("width"));
  const int height = static_cast<int>(args.integer("height"));
  const unsigned seed = static_cast<unsigned>(args.integer("seed"));
  try {
    const double offset = args.number("principal-offset");
    const int only = static_cast<int>(args.integer("cameras"));
    const int floors = static_cast<int>(args.integer("floor-frames"));
    if (floors < 1) throw std::invalid_argument("--floor-frames: at least 1");
    const bool models = args.has("models");
    const auto one = [&](int cameras, bool quick) {
      run(cameras, frames, width, height, seed, offset, models ? 1 : floors, models, quick);
    };
    if (args.has("quick")) {
      one(4, true);
    } else {
      for (int cameras : {4, 8})
        if (only == 0 || only == cameras) one(cameras, false);
      if (only != 0 && only != 4 && only != 8) one(only, false);
    }
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-rig-board: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
