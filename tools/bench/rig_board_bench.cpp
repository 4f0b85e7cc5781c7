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

// Centres after the rigid transform (Kabsch) that best maps them onto the truth's.
std::vector<glm::dvec3> aligned_centres(const std::vector<glm::dvec3>& got,
                                        const std::vector<glm::dvec3>& want) {
  glm::dvec3 mg(0.0), mw(0.0);
  for (std::size_t i = 0; i < got.size(); ++i) mg += got[i], mw += want[i];
  mg /= static_cast<double>(got.size());
  mw /= static_cast<double>(got.size());
  cv::Matx33d cov = cv::Matx33d::zeros();
  for (std::size_t i = 0; i < got.size(); ++i) {
    const glm::dvec3 a = got[i] - mg, b = want[i] - mw;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) cov(r, c) += b[r] * a[c];
  }
  cv::Mat w, u, vt;
  cv::SVD::compute(cv::Mat(cov), w, u, vt);
  cv::Mat d = cv::Mat::eye(3, 3, CV_64F);
  if (cv::determinant(u * vt) < 0) d.at<double>(2, 2) = -1;
  const cv::Matx33d R(cv::Mat(u * d * vt));
  std::vector<glm::dvec3> out;
  for (const glm::dvec3& g : got) {
    const cv::Vec3d v = R * cv::Vec3d(g.x - mg.x, g.y - mg.y, g.z - mg.z);
    out.push_back(glm::dvec3(v[0], v[1], v[2]) + mw);
  }
  return out;
}

struct Worst {
  double max_mm = 0, max_deg = 0;
};

// How the intrinsics are had: given (the truth), or from each camera's own frames, held as
// calibrated or refined in the bundle, p1 p2 fitted or held at zero, fx and fy apart or one
// (before 2026-11-26 the command's only way was p1 p2 fitted, fx and fy apart).
struct Mode {
  const char* what;
  bool given, refine, tangential, square;
};
constexpr Mode kModes[] = {
    {"given (the truth)", true, false, false, false},
    {"from each camera's own frames, held (p1 p2 fitted, fx fy apart)", false, false, true, false},
    {"from each camera's own frames, refined in the bundle, p1 p2 fitted, fx fy apart (before)",
     false, true, true, false},
    {"from each camera's own frames, refined in the bundle, p1 p2 held at 0, fx fy apart", false,
     true, false, false},
    {"from each camera's own frames, refined in the bundle, p1 p2 held at 0, fx = fy (now the "
     "default)",
     false, true, false, true},
};

void report(const test::VirtualRig& truth, const std::vector<CameraBoardViews>& views,
            const Mode& mode, const RigBoardOptions& search);

// One scene, rendered and searched once, calibrated three ways.
void run(int cameras, int frames, int width, int height, unsigned seed, double offset, bool quick) {
  test::VirtualRoom room;
  room.cameras = cameras;
  room.frames = frames;
  room.width = width;
  room.height = height;
  room.seed = seed;
  room.principal_offset_px = offset;
  room.board = {BoardKind::charuco, 7, 5, 100.0, 75.0, "DICT_4X4_50"};
  test::VirtualRig truth = test::make_virtual_rig(room);
  test::TempDir dir;
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<std::string> folders = test::render_virtual_rig(truth, room, dir.path());
  const auto t1 = std::chrono::steady_clock::now();
  RigBoardOptions search;
  search.board = room.board;
  std::vector<std::string> names;
  for (const Camera& c : truth.cameras) names.push_back(c.name);
  const std::vector<CameraBoardViews> views = find_rig_board(folders, names, search);
  const auto t2 = std::chrono::steady_clock::now();
  const auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::printf(
      "\n## %d cameras, %d frames, %dx%d px (seed %u): render %.1f s, find the board %.1f s\n",
      cameras, frames, width, height, seed, seconds(t0, t1), seconds(t1, t2));
  for (const Mode& mode : kModes) {
    report(truth, views, mode, search);
    if (quick) break;
  }
}

void report(const test::VirtualRig& truth, const std::vector<CameraBoardViews>& views,
            const Mode& mode, const RigBoardOptions& search) {
  RigBoardOptions options = search;
  options.refine_intrinsics = mode.refine;
  options.tangential_distortion = mode.tangential;
  options.square_pixels = mode.square;
  if (mode.given) options.intrinsics = Rig{truth.cameras, std::nullopt};
  const auto t2 = std::chrono::steady_clock::now();
  const RigCalibration result = calibrate_rig(views, options);
  const auto t3 = std::chrono::steady_clock::now();
  const double seconds = std::chrono::duration<double>(t3 - t2).count();

  std::printf("\n### intrinsics %s\n\n", mode.what);
  std::printf("calibrate %.2f s; %d frames with the board, floor frame %d, RMS %.3f px\n\n",
              seconds, result.frames_used, result.floor_frame, result.rms_px);
  std::vector<glm::dvec3> got, want;
  for (std::size_t k = 0; k < result.rig.cameras.size(); ++k) {
    got.push_back(result.rig.cameras[k].centre());
    want.push_back(truth.cameras[k].centre());
  }
  const std::vector<glm::dvec3> aligned = aligned_centres(got, want);
  std::printf(
      "| camera | frames with board (shown) | corners used | dropped | RMS px | corners vs "
      "truth px | position mm | angle deg | position after rigid alignment mm | fx "
      "error %% | cx err px | cy err px | angle after common rotation deg "
      "|\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
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
  double worst_common = 0;
  Worst row;
  for (std::size_t k = 0; k < result.rig.cameras.size(); ++k) {
    const Camera& c = result.rig.cameras[k];
    const Camera& t = truth.cameras[k];
    int shown = 0;
    for (bool s : truth.seen[k]) shown += s;
    const double mm = 1000 * glm::length(c.centre() - t.centre());
    const double deg = rotation_error_deg(c.rotation, t.rotation);
    row.max_mm = std::max(row.max_mm, mm);
    row.max_deg = std::max(row.max_deg, deg);
    const auto& r = result.cameras[k];
    const double common = rotation_error_deg(c.rotation * glm::transpose(g), t.rotation);
    worst_common = std::max(worst_common, common);
    std::printf(
        "| %s | %d (%d) | %d | %d | %.3f | %.3f | %.2f | %.3f | %.2f | %.2f | %.2f | %.2f | %.3f "
        "|\n",
        c.name.c_str(), r.frames_with_board, shown, r.observations, r.dropped, r.rms_px,
        corner_error_px(views[k], t, truth), mm, deg, 1000 * glm::length(aligned[k] - t.centre()),
        100 * (c.fx - t.fx) / t.fx, c.cx - t.cx, c.cy - t.cy, common);
  }
  std::printf("| **worst** | | | | | | **%.2f** | **%.3f** | | | | | %.3f |\n", row.max_mm,
              row.max_deg, worst_common);

  if (mode.given) {
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
      "[--principal-offset PX] [--quick]",
      "Board calibration of a virtual rig against the truth (synthetic "
      "renders; docs/cameras.md).");
  args.option("frames", "N", "frames per run (frame 0: the board on the floor)", "60")
      .option("width", "PX", "image width", "1280")
      .option("height", "PX", "image height", "720")
      .option("seed", "N", "scene seed", "1")
      .option("principal-offset", "PX",
              "each camera's principal point up to PX off the image centre (0: centred)", "0")
      .option("cameras", "N", "only the rig of N cameras (0: the 4- and 8-camera rigs)", "0")
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
    if (args.has("quick")) {
      run(4, frames, width, height, seed, offset, true);
    } else {
      for (int cameras : {4, 8})
        if (only == 0 || only == cameras) run(cameras, frames, width, height, seed, offset, false);
      if (only != 0 && only != 4 && only != 8)
        run(only, frames, width, height, seed, offset, false);
    }
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-rig-board: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
