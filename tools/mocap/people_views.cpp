#include "people_views.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/input_error.hpp"
#include "detector_presets.hpp"
#include "graph/graph_spec.hpp"
#include "graph/plugins.hpp"
#include "graph/validation.hpp"
#include "graph_runner.hpp"
#include "progress_bar.hpp"
#include "reconstruct_report.hpp"
#include "video/video_source.hpp"

namespace mocap::cli {
namespace {

namespace fs = std::filesystem;

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

std::string quoted(const std::string& text) { return nlohmann::json(text).dump(); }

bool holds_keypoints(const fs::path& folder) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec))
    if (e.path().filename().string().ends_with("_keypoints.json")) return true;
  return false;
}

// One source, detector and sink.openpose_json per video view.
std::string detection_graph(const std::vector<PeopleView>& views,
                            const std::vector<camera::Camera>& cameras,
                            const PeopleViewsOptions& options) {
  const DetectorPreset& preset = detector_preset(options.detector);
  std::ostringstream g;
  g << "graph: calibrate_people_detection\nnodes:\n";
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (views[i].kind != InputKind::video) continue;
    const std::string camera = quoted(cameras[i].name);
    g << "  view_" << i << ": { type: source.video, params: { path: " << quoted(views[i].path)
      << ", mode: offline, camera: " << camera;
    if (options.folder_fps) g << ", fps: " << *options.folder_fps;
    if (options.max_frames) g << ", count: " << *options.max_frames;
    g << " } }\n  detect_" << i << ": { type: " << preset.type << ", params: {";
    for (std::size_t p = 0; p < preset.params.size(); ++p)
      g << (p ? ", " : " ") << preset.params[p].first << ": " << quoted(preset.params[p].second);
    g << " } }\n  keep_" << i
      << ": { type: sink.openpose_json, params: { dir: " << quoted(views[i].json.string())
      << ", stem: " << camera << " } }\n";
  }
  g << "edges:\n";
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (views[i].kind != InputKind::video) continue;
    g << "  - [view_" << i << ".frames, detect_" << i << ".in]\n"
      << "  - [detect_" << i << ".out, keep_" << i << ".in]\n";
  }
  return g.str();
}

// "cam_01 120/300, cam_02 118/300" from the sinks' counts.
std::string progress_text(const graph::GraphStats& stats, const std::vector<PeopleView>& views,
                          const std::vector<camera::Camera>& cameras, double& fraction) {
  std::ostringstream line;
  double done = 0.0, total = 0.0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (views[i].kind != InputKind::video) continue;
    std::uint64_t in = 0;
    for (const auto& n : stats.nodes)
      if (n.node == "keep_" + std::to_string(i)) in = n.in;
    line << (line.tellp() > 0 ? ", " : "") << cameras[i].name << " " << in;
    if (views[i].frames > 0) line << "/" << views[i].frames;
    done += static_cast<double>(in);
    total += static_cast<double>(std::max<std::int64_t>(views[i].frames, 0));
  }
  fraction = total > 0 ? done / total : 0.0;
  return line.str();
}

}  // namespace

std::vector<PeopleView> open_people_views(const std::vector<std::string>& paths,
                                          const PeopleViewsOptions& options) {
  std::vector<PeopleView> views;
  for (const std::string& path : paths) {
    PeopleView& v = views.emplace_back();
    v.path = path;
    v.kind = input_kind(path);
    if (v.kind == InputKind::camera)
      throw InputError(path,
                       "a live camera cannot be a view of calibration from people: record a video "
                       "from each camera at the same time, then give the videos");
    if (v.kind == InputKind::openpose_json) {
      v.json = path;
      continue;
    }
    std::error_code ec;
    v.image_folder = fs::is_directory(path, ec);
    video::SourceOptions source_options;
    if (options.folder_fps) source_options.folder_fps = *options.folder_fps;
    const video::VideoSource source(path, source_options);  // names a garbage or empty video
    v.width = source.width();
    v.height = source.height();
    v.fps = source.fps();
    v.frames = source.frame_count();
    if (options.max_frames && (v.frames < 0 || v.frames > *options.max_frames))
      v.frames = *options.max_frames;
  }
  return views;
}

void check_people_views(const std::vector<PeopleView>& views,
                        const std::vector<camera::Camera>& cameras) {
  std::optional<std::size_t> first_video, first_known_length;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const PeopleView& v = views[i];
    if (v.kind != InputKind::video) continue;
    const camera::Camera& c = cameras[i];
    if (v.width != c.width || v.height != c.height)
      throw InputError(c.name, v.path + " is " + size_text(v.width, v.height) + " but camera '" +
                                   c.name + "' is " + size_text(c.width, c.height) +
                                   " (--intrinsics or --size): give the views in the cameras' "
                                   "order, at the calibrated size");
    if (!v.image_folder && v.fps > 0) {
      if (!first_video) {
        first_video = i;
      } else if (const PeopleView& f = views[*first_video];
                 std::abs(v.fps - f.fps) > 1e-3 * f.fps) {
        std::ostringstream what;
        what << v.path << " is " << v.fps << " fps but " << f.path << " (camera '"
             << cameras[*first_video].name << "') is " << f.fps
             << " fps: frame i of every view must be the same instant, so they must share one "
                "frame rate; resample one (e.g. ffmpeg -i IN -r "
             << f.fps << " OUT) or record them at one rate";
        throw InputError(c.name, what.str());
      }
    }
    if (v.frames > 0) {
      if (!first_known_length) {
        first_known_length = i;
      } else if (const PeopleView& f = views[*first_known_length]; v.frames != f.frames) {
        throw InputError(c.name, v.path + " has " + std::to_string(v.frames) + " frames, " +
                                     f.path + " (camera '" + cameras[*first_known_length].name +
                                     "') has " + std::to_string(f.frames) +
                                     ": the views must be in step (frame i of every view taken "
                                     "at the same instant); trim them to one length (or "
                                     "--frames N)");
      }
    }
  }
}

std::string small_keypoints_note(const PeopleView& view, const io::OpenPoseSequence& json,
                                 const camera::Camera& camera) {
  if (view.kind != InputKind::openpose_json) return "";
  double max_x = 0, max_y = 0;
  long total = 0;
  for (const People2D& frame : json.frames)
    for (const Person2D& person : frame.people)
      for (const Keypoint2D& k : person.joints) {
        if (!(k.confidence > 0) || !std::isfinite(k.x) || !std::isfinite(k.y)) continue;
        max_x = std::max<double>(max_x, k.x);
        max_y = std::max<double>(max_y, k.y);
        ++total;
      }
  if (total == 0 || max_x >= camera.width / 2.0 || max_y >= camera.height / 2.0) return "";
  std::ostringstream note;
  note.precision(0);
  note << std::fixed << "the keypoints of " << view.path << " (camera '" << camera.name << "', "
       << size_text(camera.width, camera.height) << ") never pass x " << max_x << ", y " << max_y
       << ": all in the top-left quarter of the image, as keypoints made at half the size or "
          "smaller would be; if so, the camera comes out too far away (its error does not tell)";
  return note.str();
}

void check_keypoints_fit(const PeopleView& view, const io::OpenPoseSequence& json,
                         const camera::Camera& camera) {
  if (view.kind != InputKind::openpose_json) return;
  constexpr double kMargin = 0.10;    // of the image's width and height, beyond each border
  constexpr double kMaxShare = 0.01;  // of the view's keypoints, allowed beyond the margin
  constexpr long kMinOutside = 3;
  const double w = camera.width, h = camera.height;
  const auto beyond = [&](const Keypoint2D& k) {  // how far outside, in image sizes (0: inside)
    const double dx = std::max({0.0, -k.x / w, (k.x - w) / w});
    const double dy = std::max({0.0, -k.y / h, (k.y - h) / h});
    return std::max(dx, dy);
  };
  long total = 0, outside = 0;
  double min_x = 0, max_x = 0, min_y = 0, max_y = 0, worst = 0;
  std::size_t worst_frame = 0;
  for (std::size_t f = 0; f < json.frames.size(); ++f)
    for (const Person2D& person : json.frames[f].people)
      for (const Keypoint2D& k : person.joints) {
        if (!(k.confidence > 0) || !std::isfinite(k.x) || !std::isfinite(k.y)) continue;
        min_x = total ? std::min<double>(min_x, k.x) : k.x;
        max_x = total ? std::max<double>(max_x, k.x) : k.x;
        min_y = total ? std::min<double>(min_y, k.y) : k.y;
        max_y = total ? std::max<double>(max_y, k.y) : k.y;
        ++total;
        const double b = beyond(k);
        if (b <= kMargin) continue;
        ++outside;
        if (b > worst) worst = b, worst_frame = f;
      }
  if (outside < kMinOutside || static_cast<double>(outside) <= kMaxShare * total) return;
  // The file of the farthest keypoint (frames[i] is frame number first_frame + i).
  fs::path file = view.json;
  const std::int64_t number = json.first_frame + static_cast<std::int64_t>(worst_frame);
  for (const io::FrameFile& f : io::list_frame_files(view.json))
    if (f.number == number) file = f.path;
  std::ostringstream what;
  what.precision(0);
  what << std::fixed << "camera '" << camera.name << "' is "
       << size_text(camera.width, camera.height) << " but " << outside << " of the " << total
       << " keypoints of " << view.path << " lie more than " << 100 * kMargin
       << " % of the image outside it (keypoints span x " << min_x << ".." << max_x << ", y "
       << min_y << ".." << max_y << "; the farthest in " << file.string()
       << "): give the views in the cameras' order, with the intrinsics (or "
       << "--size) of the images the keypoints were detected in";
  throw InputError(camera.name, what.str());
}

void detect_people(std::vector<PeopleView>& views, const std::vector<camera::Camera>& cameras,
                   const PeopleViewsOptions& options) {
  bool any = false;
  for (std::size_t i = 0; i < views.size(); ++i) {
    PeopleView& v = views[i];
    if (v.kind != InputKind::video) continue;
    any = true;
    v.json = options.keypoints / cameras[i].name;
    if (!holds_keypoints(v.json)) continue;
    if (!options.force)
      throw InputError(v.json.string(),
                       "holds detections already (of an earlier run?): give this folder as the "
                       "view of camera '" +
                           cameras[i].name +
                           "' to use them without detecting again, another --keypoints folder, "
                           "or --force to detect again");
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(v.json, ec))
      if (e.path().filename().string().ends_with("_keypoints.json")) fs::remove(e.path(), ec);
  }
  if (!any) return;

  graph::load_plugins_from_environment();
  graph::GraphSpec spec = graph::parse_graph_text(detection_graph(views, cameras, options),
                                                  "mocap calibrate rig --from-people");
  check_detector_model(spec);
  const graph::ResolvedGraph resolved = graph::resolve(std::move(spec));
  graph::RunOptions run_options;
  run_options.single_process = true;

  ProgressBar bar(!options.quiet && isatty(STDERR_FILENO) != 0);
  const bool lines = !options.quiet && isatty(STDERR_FILENO) == 0;
  auto last_line = std::chrono::steady_clock::now();
  const ProgressCallback progress = [&](const graph::GraphStats& stats) {
    double fraction = 0.0;
    const std::string text = progress_text(stats, views, cameras, fraction);
    bar.update("detect", fraction);
    // Not a terminal (a log): a line every 10 s.
    if (lines && std::chrono::steady_clock::now() - last_line > std::chrono::seconds(10)) {
      last_line = std::chrono::steady_clock::now();
      std::cerr << "mocap calibrate rig: detecting: " << text << " frames\n";
    }
  };
  const graph::RunResult run =
      run_graph_here(resolved, run_options, "mocap calibrate rig", progress);
  bar.finish();
  double fraction = 0.0;
  if (!options.quiet)
    std::cerr << "mocap calibrate rig: detected "
              << progress_text(run.stats, views, cameras, fraction) << " frames into "
              << options.keypoints.string() << "\n";
  if (run.stopped) throw InputError("mocap calibrate rig", "interrupted while detecting");
  if (!run.ok) throw InputError("mocap calibrate rig", "detecting people failed: " + run.error);
}

}  // namespace mocap::cli
