#include "camera/rig_calibration.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "camera/board_detection.hpp"
#include "core/input_error.hpp"

namespace mocap::camera {
namespace {

namespace fs = std::filesystem;
using namespace rig_calibration_detail;

// ---------------------------------------------------------------- finding the board in the views

bool is_image_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* known :
       {".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".ppm", ".pgm", ".pbm", ".webp"})
    if (ext == known) return true;
  return false;
}

std::vector<std::string> images_in(const std::string& folder, const std::string& camera) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec))
    if (entry.is_regular_file() && is_image_file(entry.path()))
      files.push_back(entry.path().string());
  if (ec)
    throw InputError(folder,
                     "cannot read the folder (camera " + camera + ": " + ec.message() + ")");
  if (files.empty())
    throw InputError(folder, "no image files in this folder (camera " + camera + ")");
  std::sort(files.begin(), files.end());
  return files;
}

class BoardFinder {
 public:
  BoardFinder(CameraBoardViews& view, const RigBoardOptions& options)
      : view_(view), options_(options) {}

  // Frame `index` of the view, named `where` in messages.
  void add(const std::string& where, const cv::Mat& image) {
    if (image.empty()) throw InputError(where, "unreadable image (camera " + view_.name + ")");
    if (view_.frames == 0) {
      view_.width = image.cols;
      view_.height = image.rows;
    } else if (image.cols != view_.width || image.rows != view_.height) {
      throw InputError(where, "the image is " + std::to_string(image.cols) + "x" +
                                  std::to_string(image.rows) + ", the view's first frame is " +
                                  std::to_string(view_.width) + "x" + std::to_string(view_.height));
    }
    const int index = view_.frames++;
    view_.boards.emplace_back();
    if (index % options_.step != 0) return;
    ++view_.tried;
    const detail::BoardDetection found =
        detail::detect_board(detail::to_gray(image), options_.board, options_.min_corners);
    if (!found.found()) return;
    BoardObservation seen;
    for (std::size_t i = 0; i < found.corners.image.size(); ++i) {
      const cv::Point3f& o = found.corners.object[i];
      const cv::Point2f& p = found.corners.image[i];
      seen.object_mm.push_back({o.x, o.y, o.z});
      seen.pixels.push_back({p.x, p.y});
    }
    view_.boards.back() = std::move(seen);
  }

 private:
  CameraBoardViews& view_;
  const RigBoardOptions& options_;
};

void report(const RigBoardOptions& options, const std::string& stage, double fraction) {
  if (options.progress) options.progress(stage, std::clamp(fraction, 0.0, 1.0));
}

CameraBoardViews find_in_view(const std::string& source, const std::string& name,
                              const RigBoardOptions& options) {
  CameraBoardViews view;
  view.name = name;
  view.source = source;
  BoardFinder finder(view, options);
  const std::string stage = name + ": finding the board";
  std::error_code ec;
  if (fs::is_directory(source, ec)) {
    const std::vector<std::string> files = images_in(source, name);
    for (std::size_t i = 0; i < files.size(); ++i) {
      cv::Mat image;
      try {
        image = cv::imread(files[i], cv::IMREAD_COLOR);
      } catch (const cv::Exception&) {
        image = cv::Mat();
      }
      finder.add(files[i], image);
      report(options, stage, static_cast<double>(i + 1) / static_cast<double>(files.size()));
    }
    return view;
  }
  if (!fs::exists(source, ec))
    throw InputError(source, "no such file or folder (camera " + name + ")");
  cv::VideoCapture capture;
  try {
    capture.open(source, cv::CAP_FFMPEG);  // a file: FFmpeg (see board.cpp)
  } catch (const cv::Exception&) {
  }
  if (!capture.isOpened())
    throw InputError(source, "cannot open the video (camera " + name +
                                 "; a view is a video file or a folder of images)");
  const double expected = std::max(1.0, capture.get(cv::CAP_PROP_FRAME_COUNT));
  cv::Mat frame;
  while (capture.read(frame)) {
    finder.add(source + "#" + std::to_string(view.frames), frame);
    report(options, stage, view.frames / expected);
  }
  if (view.frames == 0) throw InputError(source, "no frame could be decoded (camera " + name + ")");
  return view;
}

// ---------------------------------------------------------------- poses

cv::Matx33d matrix_of(const Camera& c) { return {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1}; }

cv::Mat distortion_of(const Camera& c) {
  if (c.distortion.empty()) return cv::Mat::zeros(1, 5, CV_64F);
  return cv::Mat(c.distortion, true).reshape(1, 1);
}

struct Rigid {
  cv::Matx33d R = cv::Matx33d::eye();
  cv::Vec3d t;
  Rigid operator*(const Rigid& o) const { return {R * o.R, R * o.t + t}; }
  Rigid inverse() const { return {R.t(), -(R.t() * t)}; }
};

Rigid rigid(const Pose& p) {
  Rigid r;
  cv::Rodrigues(cv::Vec3d(p.rotation[0], p.rotation[1], p.rotation[2]), r.R);
  r.t = {p.translation[0], p.translation[1], p.translation[2]};
  return r;
}

Pose pose_of(const Rigid& r) {
  cv::Vec3d v;
  cv::Rodrigues(r.R, v);
  return {{v[0], v[1], v[2]}, {r.t[0], r.t[1], r.t[2]}};
}

std::vector<cv::Point3f> object_points_m(const BoardObservation& b) {
  std::vector<cv::Point3f> out;
  for (const auto& o : b.object_mm)
    out.emplace_back(static_cast<float>(o[0] / 1000), static_cast<float>(o[1] / 1000),
                     static_cast<float>(o[2] / 1000));
  return out;
}

std::vector<cv::Point2f> image_points(const BoardObservation& b) {
  std::vector<cv::Point2f> out;
  for (const auto& p : b.pixels)
    out.emplace_back(static_cast<float>(p[0]), static_cast<float>(p[1]));
  return out;
}

// The board -> camera pose of one observation (IPPE for a planar target, then LM).
Rigid board_pose(const BoardObservation& b, const Camera& c) {
  const auto object = object_points_m(b);
  const auto pixels = image_points(b);
  cv::Mat rvec, tvec;
  const cv::Mat K(matrix_of(c));
  const cv::Mat D = distortion_of(c);
  cv::solvePnP(object, pixels, K, D, rvec, tvec, false, cv::SOLVEPNP_IPPE);
  cv::solvePnPRefineLM(object, pixels, K, D, rvec, tvec);
  Rigid r;
  cv::Rodrigues(rvec, r.R);
  r.t = {tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)};
  return r;
}

// The rotation nearest (Frobenius) to the mean of rotations; the per-axis median translation.
Rigid robust_mean(const std::vector<Rigid>& samples) {
  cv::Matx33d sum = cv::Matx33d::zeros();
  for (const Rigid& s : samples) sum += s.R;
  cv::Mat w, u, vt;
  cv::SVD::compute(cv::Mat(sum), w, u, vt);
  cv::Mat R = u * vt;
  if (cv::determinant(R) < 0) {
    u.col(2) *= -1;
    R = u * vt;
  }
  Rigid out;
  out.R = cv::Matx33d(R);
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values;
    for (const Rigid& s : samples) values.push_back(s.t[axis]);
    std::nth_element(values.begin(), values.begin() + static_cast<long>(values.size() / 2),
                     values.end());
    out.t[axis] = values[values.size() / 2];
  }
  return out;
}

// ---------------------------------------------------------------- intrinsics

Camera intrinsics_from_views(const CameraBoardViews& view, const RigBoardOptions& options,
                             double& rms) {
  std::vector<std::size_t> frames;
  for (std::size_t f = 0; f < view.boards.size(); ++f)
    if (view.boards[f]) frames.push_back(f);
  if (static_cast<int>(frames.size()) < options.min_intrinsic_views)
    throw InputError(view.source,
                     "camera " + view.name + ": the board was found in " +
                         std::to_string(frames.size()) + " of " + std::to_string(view.tried) +
                         " frames tried, at least " + std::to_string(options.min_intrinsic_views) +
                         " are needed for its intrinsics (or give them with --intrinsics)");
  // At most 40 views, spread over the recording: more adds time, not accuracy.
  constexpr std::size_t kMaxViews = 40;
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> pixels;
  const std::size_t take = std::min(kMaxViews, frames.size());
  for (std::size_t i = 0; i < take; ++i) {
    const BoardObservation& b = *view.boards[frames[i * frames.size() / take]];
    object.push_back(object_points_m(b));
    pixels.push_back(image_points(b));
  }
  // k3 held at zero, as OpenCV advises for ordinary lenses: a board far from the camera fills
  // little of the image, and a free k3 trades against the focal length. p1 p2 held at zero too
  // unless asked for (RigBoardOptions::tangential_distortion).
  int flags = cv::CALIB_FIX_K3;
  if (!options.tangential_distortion) flags |= cv::CALIB_ZERO_TANGENT_DIST;
  cv::Mat K = cv::Mat::eye(3, 3, CV_64F), D, rvecs, tvecs;
  if (options.square_pixels) flags |= cv::CALIB_FIX_ASPECT_RATIO;  // fx / fy of K: 1
  rms = cv::calibrateCamera(object, pixels, cv::Size(view.width, view.height), K, D, rvecs, tvecs,
                            flags);
  Camera c;
  c.name = view.name;
  c.width = view.width;
  c.height = view.height;
  c.fx = K.at<double>(0, 0);
  c.fy = K.at<double>(1, 1);
  c.cx = K.at<double>(0, 2);
  c.cy = K.at<double>(1, 2);
  c.distortion.assign(D.begin<double>(), D.end<double>());
  return c;
}

Camera given_intrinsics(const CameraBoardViews& view, const RigBoardOptions& options) {
  const Rig& rig = *options.intrinsics;
  const Camera* found = rig.find(view.name);
  if (!found) {
    std::string names;
    for (const Camera& c : rig.cameras) names += (names.empty() ? "" : ", ") + c.name;
    throw InputError(options.intrinsics_source, "has no camera '" + view.name + "' (for " +
                                                    view.source + "; it has " + names + ")");
  }
  if (found->width != view.width || found->height != view.height)
    throw InputError(options.intrinsics_source,
                     "camera " + view.name + " is " + std::to_string(found->width) + "x" +
                         std::to_string(found->height) + ", its view " + view.source + " is " +
                         std::to_string(view.width) + "x" + std::to_string(view.height));
  Camera c = *found;
  c.rotation = glm::dmat3(1.0);
  c.translation = glm::dvec3(0.0);
  return c;
}

// ---------------------------------------------------------------- the camera graph

struct Graph {
  std::size_t root = 0;
  std::vector<std::optional<std::size_t>> parent;  // per camera; root and unreached: none
  std::vector<bool> reached;
  std::vector<std::size_t> order;  // root first, each camera after its parent
};

std::vector<std::vector<int>> shared_frames(const std::vector<const CameraBoardViews*>& views) {
  const std::size_t n = views.size();
  std::vector<std::vector<int>> shared(n, std::vector<int>(n, 0));
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 1; b < n; ++b) {
      const std::size_t frames = std::min(views[a]->boards.size(), views[b]->boards.size());
      for (std::size_t f = 0; f < frames; ++f)
        if (views[a]->boards[f] && views[b]->boards[f]) ++shared[a][b], ++shared[b][a];
    }
  return shared;
}

// Prim's algorithm on the most shared frames, from the camera that saw the board most often.
Graph spanning_tree(const std::vector<std::vector<int>>& shared, const std::vector<int>& seen) {
  const std::size_t n = shared.size();
  Graph g;
  g.parent.assign(n, std::nullopt);
  g.reached.assign(n, false);
  g.root = static_cast<std::size_t>(std::max_element(seen.begin(), seen.end()) - seen.begin());
  g.reached[g.root] = true;
  g.order.push_back(g.root);
  for (;;) {
    int best = 0;
    std::size_t from = 0, to = 0;
    for (std::size_t a : g.order)
      for (std::size_t b = 0; b < n; ++b)
        if (!g.reached[b] && shared[a][b] > best) best = shared[a][b], from = a, to = b;
    if (best == 0) break;
    g.parent[to] = from;
    g.reached[to] = true;
    g.order.push_back(to);
  }
  return g;
}

// ---------------------------------------------------------------- the world from the floor board

glm::dmat3 to_glm(const cv::Matx33d& m) {
  glm::dmat3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[c][r] = m(r, c);
  return out;
}

// The frames whose board lies on the floor, checked: options.floor_frames, or floor_frame alone
// (-1: the first frame with the board).
std::vector<std::size_t> floor_frames_of(const RigBoardOptions& options,
                                         const std::vector<std::optional<std::size_t>>& board_index,
                                         const std::vector<std::size_t>& frame_of_board) {
  std::vector<int> wanted = options.floor_frames;
  if (wanted.empty())
    wanted.push_back(options.floor_frame >= 0 ? options.floor_frame
                                              : static_cast<int>(frame_of_board.front()));
  std::vector<std::size_t> out;
  for (int frame : wanted) {
    const std::string where = "floor frame " + std::to_string(frame);
    if (frame < 0 || static_cast<std::size_t>(frame) >= board_index.size())
      throw InputError(where, "the views have " + std::to_string(board_index.size()) + " frames");
    const auto f = static_cast<std::size_t>(frame);
    if (!board_index[f])
      throw InputError(
          where, "no camera of the rig saw the board in this frame (try every frame: step 1)");
    if (std::find(out.begin(), out.end(), f) != out.end())
      throw InputError(where, "is listed twice");
    out.push_back(f);
  }
  return out;
}

// The board points seen in one board pose of the bundle, each once (several cameras see the same
// corner).
std::vector<std::array<double, 3>> distinct_corners(const BundleProblem& problem,
                                                    std::size_t board) {
  std::vector<std::array<double, 3>> out;
  for (const CornerObservation& o : problem.corners)
    if (o.frame == board) out.push_back(o.object_m);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void check(const RigBoardOptions& o) {
  check_board(o.board);
  if (o.step < 1) throw std::invalid_argument("rig calibration: step must be at least 1");
  if (o.min_corners < 4) throw std::invalid_argument("rig calibration: at least 4 corners");
  if (o.min_intrinsic_views < 3)
    throw std::invalid_argument("rig calibration: at least 3 views for intrinsics");
  if (!(o.outlier_factor > 1)) throw std::invalid_argument("rig calibration: outlier factor > 1");
  if (o.outlier_rounds < 0) throw std::invalid_argument("rig calibration: outlier rounds >= 0");
  if (!(o.board_thickness_mm >= 0 && std::isfinite(o.board_thickness_mm)))
    throw std::invalid_argument("rig calibration: thickness must be finite and >= 0");
}

}  // namespace

namespace rig_calibration_detail {

namespace {
cv::Vec3d column(const cv::Matx33d& m, int c) { return {m(0, c), m(1, c), m(2, c)}; }
}  // namespace

FloorFit fit_floor(const std::vector<Pose>& boards,
                   const std::vector<std::vector<std::array<double, 3>>>& corners) {
  if (boards.empty() || boards.size() != corners.size())
    throw std::invalid_argument("fit_floor: one set of corners per board, at least one board");
  std::vector<Rigid> poses;
  std::vector<std::vector<cv::Vec3d>> points(boards.size());
  cv::Vec3d centroid(0, 0, 0);
  std::size_t count = 0;
  for (std::size_t b = 0; b < boards.size(); ++b) {
    poses.push_back(rigid(boards[b]));
    for (const auto& c : corners[b]) {
      points[b].push_back(poses[b].R * cv::Vec3d(c[0], c[1], c[2]) + poses[b].t);
      centroid += points[b].back();
      ++count;
    }
  }
  if (count < 3) throw std::invalid_argument("fit_floor: fewer than 3 corners");
  centroid *= 1.0 / static_cast<double>(count);
  cv::Matx33d scatter = cv::Matx33d::zeros();
  for (const auto& board : points)
    for (const cv::Vec3d& p : board) scatter += (p - centroid) * (p - centroid).t();
  cv::Mat w, u, vt;
  cv::SVD::compute(cv::Mat(scatter), w, u, vt);
  if (!(w.at<double>(1) > 1e-12 * w.at<double>(0)))
    throw std::invalid_argument("fit_floor: the corners lie on one line");
  cv::Vec3d up(u.at<double>(0, 2), u.at<double>(1, 2), u.at<double>(2, 2));
  // A board lying face up: its z points into the floor.
  const cv::Vec3d first_up = -column(poses[0].R, 2);
  if (up.dot(first_up) < 0) up = -up;
  const cv::Vec3d origin = poses[0].t - up * up.dot(poses[0].t - centroid);
  cv::Vec3d x = column(poses[0].R, 0);
  x = cv::normalize(x - up * up.dot(x));
  const cv::Vec3d y = up.cross(x);
  Rigid world;
  world.R = cv::Matx33d(x[0], x[1], x[2], y[0], y[1], y[2], up[0], up[1], up[2]);
  world.t = -(world.R * origin);

  FloorFit fit;
  fit.world_from_bundle = pose_of(world);
  for (std::size_t b = 0; b < boards.size(); ++b) {
    double off = 0.0;
    for (const cv::Vec3d& p : points[b]) off = std::max(off, std::abs(up.dot(p - centroid)));
    fit.max_off_m.push_back(off);
    const double cosine = std::clamp(-up.dot(column(poses[b].R, 2)), -1.0, 1.0);
    fit.tilt_deg.push_back(std::acos(cosine) * 180.0 / std::acos(-1.0));
  }
  return fit;
}

}  // namespace rig_calibration_detail

std::vector<CameraBoardViews> find_rig_board(const std::vector<std::string>& views,
                                             const std::vector<std::string>& names,
                                             const RigBoardOptions& options) {
  check(options);
  if (views.size() != names.size())
    throw std::invalid_argument("find_rig_board: one name per view");
  std::vector<CameraBoardViews> out;
  for (std::size_t i = 0; i < views.size(); ++i)
    out.push_back(find_in_view(views[i], names[i], options));
  const bool equal = std::all_of(out.begin(), out.end(), [&](const CameraBoardViews& v) {
    return v.frames == out.front().frames;
  });
  if (!equal) {
    std::string counts;
    for (const auto& v : out)
      counts +=
          (counts.empty() ? "" : ", ") + v.name + " (" + v.source + ") " + std::to_string(v.frames);
    throw InputError("views", "different frame counts: " + counts +
                                  ". Frame i of every view must be taken at the same instant; "
                                  "trim the views to the same frames");
  }
  return out;
}

RigCalibration calibrate_rig(const std::vector<CameraBoardViews>& all_views,
                             const RigBoardOptions& options) {
  check(options);
  if (all_views.size() < 2)
    throw InputError(
        "views", "a rig needs at least 2 cameras, " + std::to_string(all_views.size()) + " given");
  RigCalibration result;
  const std::string board = describe(options.board);

  // Cameras that never saw the board.
  std::vector<const CameraBoardViews*> views;
  for (const CameraBoardViews& v : all_views) {
    const auto seen = std::count_if(v.boards.begin(), v.boards.end(),
                                    [](const auto& b) { return b.has_value(); });
    if (seen > 0) {
      views.push_back(&v);
      continue;
    }
    const std::string what = "camera " + v.name + ": the board (" + board +
                             ") was not found in any of the " + std::to_string(v.tried) +
                             " frames tried";
    if (!options.drop_unconnected) throw InputError(v.source, what);
    result.notes.push_back(what + "; left out of the rig");
  }
  if (views.size() < 2) throw InputError("views", "fewer than 2 cameras saw the board");

  // Intrinsics.
  std::vector<Camera> cameras;
  std::vector<double> intrinsic_rms;
  for (std::size_t i = 0; i < views.size(); ++i) {
    report(options, "intrinsics", static_cast<double>(i) / static_cast<double>(views.size()));
    double rms = 0.0;
    cameras.push_back(options.intrinsics ? given_intrinsics(*views[i], options)
                                         : intrinsics_from_views(*views[i], options, rms));
    cameras.back().name = views[i]->name;
    intrinsic_rms.push_back(rms);
  }

  // Board poses per camera, the camera graph, its unconnected cameras.
  report(options, "camera graph", 0.0);
  std::vector<int> seen;
  for (const auto* v : views)
    seen.push_back(static_cast<int>(std::count_if(v->boards.begin(), v->boards.end(),
                                                  [](const auto& b) { return b.has_value(); })));
  const auto shared = shared_frames(views);
  const Graph graph = spanning_tree(shared, seen);
  std::vector<std::size_t> kept;  // indices into views, in view order
  std::string left_out;
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (graph.reached[i]) {
      kept.push_back(i);
      continue;
    }
    left_out += (left_out.empty() ? "" : ", ") + views[i]->name + " (" + views[i]->source + ")";
  }
  if (!left_out.empty()) {
    const std::string what = "camera(s) " + left_out +
                             " never see the board in a frame that the other cameras (from " +
                             views[graph.root]->name + ") see it in";
    if (!options.drop_unconnected)
      throw InputError("views", what +
                                    ": film the board where they overlap, or leave them out "
                                    "(--drop-unconnected)");
    result.notes.push_back(what + "; left out of the rig");
  }

  const std::size_t frames = views.front()->boards.size();
  std::vector<std::vector<std::optional<Rigid>>> board_in_camera(views.size());
  for (std::size_t i : kept) {
    board_in_camera[i].resize(frames);
    for (std::size_t f = 0; f < std::min(frames, views[i]->boards.size()); ++f)
      if (views[i]->boards[f]) board_in_camera[i][f] = board_pose(*views[i]->boards[f], cameras[i]);
  }
  // World = the root camera's frame until the floor board sets it.
  std::vector<Rigid> camera_from_world(views.size());
  for (std::size_t i : graph.order) {
    if (!graph.parent[i]) continue;
    const std::size_t p = *graph.parent[i];
    std::vector<Rigid> samples;  // child <- parent, one per shared frame
    for (std::size_t f = 0; f < frames; ++f)
      if (board_in_camera[i][f] && board_in_camera[p][f])
        samples.push_back(*board_in_camera[i][f] * board_in_camera[p][f]->inverse());
    camera_from_world[i] = robust_mean(samples) * camera_from_world[p];
  }

  // The bundle: boards of frames seen by a kept camera, from the camera that saw most corners.
  BundleProblem problem;
  std::vector<std::optional<std::size_t>> board_index(frames);
  std::vector<std::size_t> frame_of_board;
  for (std::size_t f = 0; f < frames; ++f) {
    std::optional<std::size_t> best;
    for (std::size_t i : kept)
      if (board_in_camera[i][f] &&
          (!best || views[i]->boards[f]->pixels.size() > views[*best]->boards[f]->pixels.size()))
        best = i;
    if (!best) continue;
    board_index[f] = problem.board_poses.size();
    frame_of_board.push_back(f);
    problem.board_poses.push_back(
        pose_of(camera_from_world[*best].inverse() * *board_in_camera[*best][f]));
  }
  std::vector<std::size_t> kept_position(views.size());
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const std::size_t i = kept[k];
    kept_position[i] = k;
    problem.cameras.push_back(cameras[i]);
    problem.camera_poses.push_back(pose_of(camera_from_world[i]));
    for (std::size_t f = 0; f < frames; ++f) {
      if (!board_in_camera[i][f]) continue;
      const BoardObservation& b = *views[i]->boards[f];
      for (std::size_t c = 0; c < b.pixels.size(); ++c)
        problem.corners.push_back(
            {k,
             *board_index[f],
             {b.object_mm[c][0] / 1000, b.object_mm[c][1] / 1000, b.object_mm[c][2] / 1000},
             b.pixels[c],
             true});
    }
  }
  problem.fixed_camera = kept_position[graph.root];
  problem.refine_intrinsics = options.refine_intrinsics;
  problem.refine_tangential = options.tangential_distortion;
  problem.square_pixels = options.square_pixels && !options.intrinsics;

  std::vector<double> errors;
  for (int round = 0; round <= options.outlier_rounds; ++round) {
    report(options, "bundle adjustment", static_cast<double>(round) / (options.outlier_rounds + 1));
    bundle_adjust(problem, errors);
    if (round == options.outlier_rounds) break;
    // Never below half a pixel: on clean data 3x the median would cut into the good corners.
    if (!drop_outliers(problem, errors, options.outlier_factor, 0.5)) break;
  }
  report(options, "bundle adjustment", 1.0);

  // The floor frames, and the world from their boards.
  const std::vector<std::size_t> floors = floor_frames_of(options, board_index, frame_of_board);
  std::vector<Pose> floor_boards;
  std::vector<std::vector<std::array<double, 3>>> floor_corners;
  for (std::size_t f : floors) {
    floor_boards.push_back(problem.board_poses[*board_index[f]]);
    floor_corners.push_back(distinct_corners(problem, *board_index[f]));
  }
  const FloorFit fit = fit_floor(floor_boards, floor_corners);
  const Rigid old_from_world = rigid(fit.world_from_bundle).inverse();
  for (std::size_t i = 0; i < floors.size(); ++i) {
    const FloorFrameReport r{static_cast<int>(floors[i]), static_cast<int>(floor_corners[i].size()),
                             1000 * fit.max_off_m[i], fit.tilt_deg[i]};
    result.floor_frames.push_back(r);
    if (r.max_off_mm > kFloorToleranceMm) {
      std::ostringstream note;
      note << std::fixed << std::setprecision(1) << "floor frame " << r.frame
           << ": its board lies up to " << r.max_off_mm << " mm off the plane of the floor frames"
           << " (tilted " << r.tilt_deg << " degrees): is it flat on the floor?";
      result.notes.push_back(note.str());
    }
  }
  const int floor = static_cast<int>(floors.front());

  // The rig and its report.
  double all_squared = 0.0;
  int all_count = 0;
  for (std::size_t k = 0; k < kept.size(); ++k) {
    Camera c = problem.cameras[k];
    const Rigid pose = rigid(problem.camera_poses[k]) * old_from_world;
    c.rotation = to_glm(pose.R);
    c.translation = {pose.t[0], pose.t[1], pose.t[2]};
    result.rig.cameras.push_back(c);
    CameraCalibrationReport r;
    r.name = c.name;
    r.frames_with_board = seen[kept[k]];
    r.intrinsics_rms_px = intrinsic_rms[kept[k]];
    double squared = 0.0;
    for (std::size_t o = 0; o < problem.corners.size(); ++o) {
      if (problem.corners[o].camera != k) continue;
      if (!problem.corners[o].active) {
        ++r.dropped;
        continue;
      }
      ++r.observations;
      squared += errors[o] * errors[o];
    }
    all_squared += squared;
    all_count += r.observations;
    r.rms_px = r.observations ? std::sqrt(squared / r.observations) : 0.0;
    result.cameras.push_back(r);
  }
  result.rig.floor = GroundPlane{{0.0, 0.0, 1.0}, options.board_thickness_mm / 1000.0};
  result.floor_frame = floor;
  result.frames_used = static_cast<int>(frame_of_board.size());
  result.rms_px = all_count ? std::sqrt(all_squared / all_count) : 0.0;
  return result;
}

RigCalibration calibrate_rig_from_board(const std::vector<std::string>& views,
                                        const std::vector<std::string>& names,
                                        const RigBoardOptions& options) {
  return calibrate_rig(find_rig_board(views, names, options), options);
}

}  // namespace mocap::camera
