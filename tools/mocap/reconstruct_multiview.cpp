// `mocap reconstruct --calibration RIG VIEW1 VIEW2 ... --out DIR`: several calibrated views of one
// scene (each a folder of OpenPose JSON, a video file, an image folder or a live camera, in the
// rig's camera order) to the people in the rig's world: poses.jsonl with each person's
// joints_world, one BVH per person (y up, the floor at y = 0) and summary.json. Builds the graph of
// graphs/multiview_json.yaml (or its video or live form) for the number of views, after checking
// what can be checked before DIR is touched: the rig, one view per camera, the views' image sizes
// against the rig's, files and cameras not mixed.

#include <pthread.h>
#include <unistd.h>

#include <csignal>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "camera.hpp"
#include "camera/rig_file.hpp"
#include "cli_args.hpp"
#include "core/input_error.hpp"
#include "core/install_paths.hpp"
#include "detector_presets.hpp"
#include "eval_report.hpp"
#include "graph/graph_spec.hpp"
#include "graph/plugins.hpp"
#include "graph/validation.hpp"
#include "graph_runner.hpp"
#include "input_kind.hpp"
#include "io/openpose_json.hpp"
#include "multiview/rig_reconstruction.hpp"
#include "multiview/view_check.hpp"
#include "output_files.hpp"
#include "posedb/database.hpp"
#include "progress_bar.hpp"
#include "reconstruct_report.hpp"
#include "video/video_source.hpp"
#include "view_offsets.hpp"

namespace mocap::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Files are joined by frame number; cameras (V4L2 devices, streams, GigE/USB3 Vision) are live and
// joined by capture time.
using ViewKind = InputKind;

// A GigE Vision / USB3 Vision camera as a view: aravis:ID, the ID being what `mocap camera list`
// shows (device id, serial or address) and what source.aravis's `id` takes.

struct View {
  std::string path;
  ViewKind kind = ViewKind::openpose_json;
  bool aravis = false;  // kind camera: through source.aravis (else source.video, live)
  const camera::Camera* camera = nullptr;
  std::int64_t frames = -1;
  double fps = 0.0;                             // videos: their own rate
  std::int64_t frame_offset = 0;                // added to the view's frame numbers (--offsets)
  std::optional<camera::ViewOffset> estimated;  // --offsets auto
  camera::BodySequence keypoints;               // JSON views: the body joints of every frame
};

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// The keypoints of a JSON view must lie in its camera's image: keypoints beyond it mean the view
// is another camera's (the order of the views) or of other images. Unreadable frames are left to
// the source, which names them and goes on.
void check_json_view(View& view, const std::string& rig_file) {
  io::OpenPoseOptions layout;  // as source.openpose_json reads them (layout auto)
  layout.body25 = io::Body25Choice::detect;
  const io::OpenPoseSequence sequence = io::read_openpose_folder(view.path, layout);
  view.frames = static_cast<std::int64_t>(sequence.frames.size());
  view.keypoints = camera::body_sequence(sequence.frames);
  float max_x = 0.0f, max_y = 0.0f;
  for (const People2D& frame : sequence.frames) {
    for (const Person2D& p : frame.people) {
      for (const Keypoint2D& k : p.joints) {
        if (!(k.confidence > 0.0f) || !std::isfinite(k.x) || !std::isfinite(k.y)) continue;
        max_x = std::max(max_x, k.x);
        max_y = std::max(max_y, k.y);
      }
    }
  }
  const camera::Camera& c = *view.camera;
  if (max_x > static_cast<float>(c.width) + 1.0f || max_y > static_cast<float>(c.height) + 1.0f) {
    std::ostringstream what;
    what << "the keypoints of " << view.path << " reach (" << max_x << ", " << max_y
         << ") px, outside camera '" << c.name << "' of " << rig_file << " ("
         << size_text(c.width, c.height)
         << "): give the views in the rig's camera order, each from its camera's images";
    throw InputError(c.name, what.str());
  }
}

void check_video_view(View& view, const std::string& rig_file, const Args& args) {
  video::SourceOptions options;
  if (args.has("fps")) options.folder_fps = options.fps = args.number("fps");
  const video::VideoSource source(view.path, options);
  const camera::Camera& c = *view.camera;
  if (source.width() != c.width || source.height() != c.height) {
    throw InputError(c.name, view.path + " is " + size_text(source.width(), source.height()) +
                                 " but camera '" + c.name + "' of " + rig_file + " is " +
                                 size_text(c.width, c.height) +
                                 ": give the views in the rig's camera order, at the calibrated "
                                 "size");
  }
  view.frames = source.frame_count();
  view.fps = source.fps();
}

std::string size_mismatch(const View& view, int width, int height, const std::string& rig_file,
                          const std::string& what_to_do) {
  const camera::Camera& c = *view.camera;
  return view.path + " delivers " + size_text(width, height) + " but camera '" + c.name + "' of " +
         rig_file + " is " + size_text(c.width, c.height) + ": " + what_to_do;
}

// A camera is opened once to read the size it delivers (then closed: the graph opens it again).
// A V4L2 device is asked for its camera's calibrated size and --fps; a GigE camera keeps its own
// region (cropping it would move the principal point): it must already be at the calibrated size.
void check_camera_view(View& view, const std::string& rig_file, const Args& args) {
  const camera::Camera& c = *view.camera;
  if (view.aravis) {
    aravis::CameraSettings settings;
    settings.id = view.path.substr(kAravisPrefix.size());
    if (args.has("fps")) settings.frame_rate = args.number("fps");
    aravis::Region region;
    try {
      const aravis::Camera probe(settings);
      region = probe.region();
      view.fps = probe.frame_rate();
    } catch (const std::exception& e) {
      throw InputError(c.name, "cannot open " + view.path + " (" + e.what() +
                                   "); `mocap camera list` shows the cameras Aravis sees");
    }
    if (region.width != c.width || region.height != c.height)
      throw InputError(c.name, size_mismatch(view, region.width, region.height, rig_file,
                                             "set the camera's region to the calibrated size "
                                             "(or calibrate at the size it delivers)"));
    return;
  }
  video::SourceOptions options;
  options.width = c.width;
  options.height = c.height;
  if (args.has("fps")) options.fps = args.number("fps");
  std::optional<video::VideoSource> opened;
  try {
    opened.emplace(view.path, options);
  } catch (const std::exception& e) {
    throw InputError(c.name, e.what());  // names the device or stream, and what to do
  }
  const video::VideoSource& source = *opened;
  if (source.width() != c.width || source.height() != c.height)
    throw InputError(c.name, size_mismatch(view, source.width(), source.height(), rig_file,
                                           "give the views in the rig's camera order, each a "
                                           "camera that delivers its calibrated size"));
  view.fps = source.fps();
}

// The frames the views are checked against each other on (multiview/view_check.hpp): the first
// of them in which every view shows somebody, at most ViewCheckOptions::max_frames, a bounded time.
constexpr std::int64_t kCheckedFrames = 300;

// JSON views checked against each other before anything is written: views given in another order
// than the rig's cameras (any permutation) or a view's keypoints made at another image size are
// refused, naming them, the order to give them in and the errors (unless --ignore-view-check:
// then printed as a warning); a camera far worse than the rest that neither explains, or every
// camera far off (the rig may not be these views'), is a warning only (the rig may be off, which
// the run cannot mend but may live with).
// The views are taken as the graph joins them: view i's frame t - offset at frame t.
void check_views_agree(const std::vector<View>& views, bool ignore) {
  std::vector<camera::Camera> cameras;
  std::vector<camera::BodySequence> aligned(views.size());
  std::vector<std::string> labels;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const View& v = views[i];
    if (v.kind != ViewKind::openpose_json) return;  // videos: the keypoints come later
    cameras.push_back(*v.camera);
    labels.push_back("view " + std::to_string(i + 1) + " (" + v.camera->name + ", " + v.path + ")");
    for (std::int64_t t = 0; t < kCheckedFrames; ++t) {
      const std::int64_t f = t - v.frame_offset;
      const bool inside = f >= 0 && f < static_cast<std::int64_t>(v.keypoints.size());
      aligned[i].push_back(inside ? v.keypoints[static_cast<std::size_t>(f)]
                                  : std::vector<camera::BodyKeypoints>{});
    }
  }
  const multiview::ViewCheck check = multiview::check_views(cameras, aligned);
  const std::vector<std::string> findings = multiview::describe(check, cameras, labels);
  if (findings.empty()) return;
  std::string text;
  for (const std::string& line : findings) text += (text.empty() ? "" : "; ") + line;
  if (!check.explained() || ignore) {
    std::cerr << "mocap reconstruct: warning: " << text << "\n";
    return;
  }
  throw InputError("the views", text + " (checked on " + std::to_string(check.errors.frames_used) +
                                    " frames; --ignore-view-check goes on anyway)");
}

// Files are joined by frame number, cameras by capture time: one run takes one or the other.
void refuse_mixed_views(const std::vector<View>& views) {
  const auto camera = std::find_if(views.begin(), views.end(),
                                   [](const View& v) { return v.kind == ViewKind::camera; });
  const auto file = std::find_if(views.begin(), views.end(),
                                 [](const View& v) { return v.kind != ViewKind::camera; });
  if (camera == views.end() || file == views.end()) return;
  throw InputError(camera->camera->name,
                   camera->path + " is a live camera but " + file->path + " (camera '" +
                       file->camera->name +
                       "') is a file: files are joined frame by frame, cameras by the time "
                       "they took their frames, so one run takes either files or cameras; "
                       "record the cameras to files first, or give a camera for every view");
}

// The views are joined frame by frame: videos at different rates would drift apart (29.97 against
// 30 fps: a frame every 33 s), so they are refused, naming both (not resampled: which frames to
// drop or repeat is the user's choice, and a tool like ffmpeg -r does it once).
void check_frame_rates(const std::vector<View>& views) {
  const View* first = nullptr;
  for (const View& v : views) {
    if (v.kind != ViewKind::video || v.fps <= 0.0) continue;  // no rate of its own, or live
    if (!first) {
      first = &v;
    } else if (std::abs(v.fps - first->fps) > 1e-3 * first->fps) {
      std::ostringstream what;
      what << v.path << " is " << v.fps << " fps but " << first->path << " (camera '"
           << first->camera->name << "') is " << first->fps
           << " fps: the views are joined frame by frame, so they must share one frame rate; "
              "resample one (e.g. ffmpeg -i IN -r "
           << first->fps << " OUT) or record them at one rate";
      throw InputError(v.camera->name, what.str());
    }
  }
}

// One view per rig camera, in its order: a camera without a view or a view without a camera is
// refused, naming it.
std::vector<View> match_views(const camera::Rig& rig, const std::vector<std::string>& paths,
                              const std::string& rig_file) {
  if (paths.size() < rig.cameras.size()) {
    throw InputError(rig.cameras[paths.size()].name,
                     "no view for this camera: " + rig_file + " has " +
                         std::to_string(rig.cameras.size()) + " cameras, " +
                         std::to_string(paths.size()) +
                         " views were given; give one view per camera, in the rig's order");
  }
  if (paths.size() > rig.cameras.size()) {
    throw InputError(paths[rig.cameras.size()], "no camera for this view: " + rig_file + " has " +
                                                    std::to_string(rig.cameras.size()) +
                                                    " cameras, " + std::to_string(paths.size()) +
                                                    " views were given");
  }
  std::vector<View> views;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    View& v = views.emplace_back();
    v.path = paths[i];
    v.kind = input_kind(paths[i]);
    v.aravis = paths[i].starts_with(kAravisPrefix);
    v.camera = &rig.cameras[i];
  }
  return views;
}

std::string quoted(const std::string& text) { return json(text).dump(); }

void block_stop_signals() {
  sigset_t stop;
  sigemptyset(&stop);
  sigaddset(&stop, SIGINT);
  sigaddset(&stop, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop, nullptr);
}

// Live: a set the cameras' frames could not complete goes on after this wait (a stalled or lost
// camera holds the others back no longer; source.aravis reopens a lost one by itself).
constexpr int kLiveSyncWaitMs = 200;
// Live: how long the solve waits for a view of a set that the limiter passed without it (its
// camera stalled): longer than one detection takes under load, so that a complete set never goes
// on partial because one detector finished late.
constexpr int kLiveSolveWaitMs = 1000;

void write_detector(std::ostringstream& g, std::size_t i, const std::string& detector) {
  const DetectorPreset& preset = detector_preset(detector);
  g << "  detect_" << i << ": { type: " << preset.type << ", params: {";
  for (std::size_t p = 0; p < preset.params.size(); ++p)
    g << (p ? ", " : " ") << preset.params[p].first << ": " << quoted(preset.params[p].second);
  g << " } }\n";
}

// A live camera's source node: GigE/USB3 Vision through Aravis, anything else (a V4L2 device, a
// stream) through source.video in live mode, a device asked for its camera's calibrated size.
void write_camera_source(std::ostringstream& g, std::size_t i, const View& v, const Args& args) {
  const std::string camera = quoted(v.camera->name);
  const std::string fps = args.has("fps") ? ", fps: " + args.get("fps") : "";
  if (v.aravis) {
    g << "  view_" << i
      << ": { type: source.aravis, params: { id: " << quoted(v.path.substr(kAravisPrefix.size()))
      << fps << ", camera: " << camera << " } }\n";
    return;
  }
  g << "  view_" << i << ": { type: source.video, params: { path: " << quoted(v.path)
    << ", mode: live, width: " << v.camera->width << ", height: " << v.camera->height << fps
    << ", camera: " << camera << " } }\n";
}

// Live cameras' frames are joined by capture time first (flow.set_limiter): a set goes to every
// camera's detector at once, and only while all of them are idle, so each detector works on the
// same instants and the people join complete even when detection is slower than the cameras. The
// limiter numbers the sets; the solve joins by that number, and waits for a view the limiter had
// no frame for (a stalled camera) at most its sync_wait_ms.
std::string live_graph_part(const std::vector<View>& views, double fps, const std::string& detector,
                            const Args& args, std::ostringstream& edges) {
  std::ostringstream g;
  for (std::size_t i = 0; i < views.size(); ++i) {
    write_camera_source(g, i, views[i], args);
    write_detector(g, i, detector);
    edges << "  - [view_" << i << ".frames, limit.frames:" << i << "]\n"
          << "  - [limit.frames:" << i << ", detect_" << i << ".in]\n"
          << "  - [detect_" << i << ".out, solve.view:" << i << "]\n";
  }
  // Over half a frame period: free-running cameras' frames are up to half a period apart, and a
  // shorter tolerance splits each instant into two partial sets at an unlucky phase
  // (docs/cameras.md, "Free-running RTSP cameras"); under a period, so a set never reaches a
  // camera's next frame. Triggered cameras are within a millisecond either way.
  const double tolerance_ms = 0.6 * 1000.0 / fps;
  g << "  limit: { type: flow.set_limiter, params: { sync_tolerance_ms: "
    << json(tolerance_ms).dump() << ", sync_wait_ms: " << kLiveSyncWaitMs << " } }\n";
  return g.str();
}

// The graph of graphs/multiview_json.yaml (and its video and live forms) for these views.
std::string graph_text(const std::vector<View>& views, const std::string& rig_file,
                       const fs::path& out, double fps, const std::string& detector,
                       const std::string& trc_world_up, const std::string& fit, const Args& args) {
  const std::string rate = json(fps).dump();
  const bool live = views.front().kind == ViewKind::camera;  // not mixed (refuse_mixed_views)
  std::ostringstream g, edges;
  g << "graph: multiview_reconstruct\nnodes:\n";
  if (live) g << live_graph_part(views, fps, detector, args, edges);
  for (std::size_t i = 0; !live && i < views.size(); ++i) {
    const View& v = views[i];
    const std::string camera = quoted(v.camera->name);
    if (v.kind == ViewKind::openpose_json) {
      g << "  view_" << i << ": { type: source.openpose_json, params: { path: " << quoted(v.path)
        << ", fps: " << rate << ", camera: " << camera << ", frame_offset: " << v.frame_offset
        << " } }\n";
      edges << "  - [view_" << i << ".out, solve.view:" << i << "]\n";
      continue;
    }
    g << "  view_" << i << ": { type: source.video, params: { path: " << quoted(v.path)
      << ", mode: offline, fps: " << rate << ", camera: " << camera
      << ", frame_offset: " << v.frame_offset << " } }\n";
    write_detector(g, i, detector);
    edges << "  - [view_" << i << ".frames, detect_" << i << ".in]\n"
          << "  - [detect_" << i << ".out, solve.view:" << i << "]\n";
  }
  g << "  solve: { type: multiview.reconstruct, params: { rig: " << quoted(rig_file)
    << ", fps: " << rate << ", fit: " << fit;
  if (args.has("db") && fit != "off") g << ", prior_db: " << quoted(args.get("db"));
  // Live: the limiter's set numbers are the frames; a set the limiter passed without a view waits
  // for it this long (longer than a detection takes, or complete sets would go on partial).
  if (live) g << ", sync_by: frame, sync_wait_ms: " << kLiveSolveWaitMs;
  g << " } }\n"
    << "  jsonl: { type: sink.jsonl, params: { path: " << quoted((out / "poses.jsonl").string())
    << " } }\n"
    << "  bvh: { type: sink.bvh_joints, params: { dir: " << quoted(out.string())
    << ", fps: " << rate << " } }\n"
    << "  trc: { type: sink.trc, params: { path: " << quoted((out / "person_{id}.trc").string())
    << ", fps: " << rate << ", world_up: " << trc_world_up << " } }\nedges:\n"
    << edges.str()
    << "  - [solve.out, jsonl.in]\n  - [solve.out, bvh.in]\n  - [solve.out, trc.in]\n";
  return g.str();
}

// --offsets: per view the frames its numbering is moved by (its frame i shows the first view's
// frame i + offset), given as numbers or estimated from the keypoints of JSON views (auto).
// Estimates keep their fraction in the summary; the views are moved by whole frames, shifted so
// that the earliest view starts at frame 0.
void apply_offsets(std::vector<View>& views, const camera::Rig& rig, const Args& args) {
  std::vector<double> offsets;
  if (args.get("offsets") == "auto") {
    std::vector<std::string> folders;
    for (const View& v : views) {
      if (v.kind != ViewKind::openpose_json)
        throw InputError("--offsets", "auto needs keypoints: " + v.path +
                                          " is not an OpenPose JSON folder; give the offsets "
                                          "as numbers (e.g. --offsets 0,3,-2)");
      folders.push_back(v.path);
    }
    io::OpenPoseOptions keypoints;  // as source.openpose_json reads them (layout auto)
    keypoints.body25 = io::Body25Choice::detect;
    const ViewOffsets estimated = estimate_view_offsets(
        rig, folders, keypoints, 0, camera::OffsetOptions{}, "mocap reconstruct");
    for (std::size_t i = 0; i < views.size(); ++i) {
      const camera::ViewOffset& o = estimated.offsets[i];
      if (i > 0 && !o.found)
        throw InputError(views[i].camera->name,
                         "no frame offset found for " + views[i].path + ": " + o.problem +
                             "; give the offsets as numbers (--offsets 0,N,...)");
      views[i].estimated = o;
      offsets.push_back(o.frames);
      if (i > 0)
        std::cerr << "mocap reconstruct: " << views[i].camera->name << " (" << views[i].path
                  << ") starts " << o.frames << " frames after " << views[0].camera->name
                  << " (contrast " << o.contrast << ")\n";
    }
  } else {
    offsets = args.numbers("offsets");
    if (offsets.size() != views.size())
      throw InputError("--offsets", std::to_string(offsets.size()) + " offsets for " +
                                        std::to_string(views.size()) +
                                        " views: give one per view (the first is usually 0) or "
                                        "auto");
  }
  std::int64_t earliest = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    views[i].frame_offset = std::llround(offsets[i]);
    earliest = std::min(earliest, views[i].frame_offset);
  }
  for (View& v : views) v.frame_offset -= earliest;
}

std::string kind_name(const View& v) {
  switch (v.kind) {
    case ViewKind::openpose_json:
      return "openpose_json";
    case ViewKind::video:
      return "video";
    case ViewKind::camera:
      return "camera";
  }
  return "?";
}

json offsets_json(const View& v) {
  json o = {{"applied_frames", v.frame_offset}};
  if (v.estimated) {
    o["estimated_frames"] = v.estimated->frames;
    o["contrast"] = v.estimated->contrast;
  }
  return o;
}

// A live view: the frames its source delivered and its last state (a camera lost and not back
// says "lost, reconnecting"), so that the summary names a camera that stopped mid-run.
void add_camera_state(json& entry, const graph::GraphStats& stats, const std::string& node) {
  for (const graph::NodeStats& n : stats.nodes) {
    if (n.node != node) continue;
    entry["frames_received"] = n.out;
    entry["state"] = n.status.empty() ? "streaming" : n.status;
  }
}

}  // namespace

bool asks_for_multiview(int argc, char** argv) {
  for (int i = 0; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--calibration" || arg.starts_with("--calibration=")) return true;
  }
  return false;
}

int reconstruct_multiview_command(int argc, char** argv) {
  Args args(
      "mocap reconstruct --calibration RIG VIEW1 VIEW2 ... --out DIR [--fps F] [--force]",
      "Reconstructs every person seen by several calibrated cameras, in the rig's world. Each\n"
      "VIEW is a folder of OpenPose JSON, a video file or a folder of images (people found by the\n"
      "detector), one per camera of RIG, in the rig's order; or, live, every VIEW a camera: a\n"
      "V4L2 device (/dev/videoN), a stream URL (rtsp://...) or a GigE/USB3 Vision camera\n"
      "(aravis:ID, ID as `mocap camera list` shows it: device id, serial or address), joined by\n"
      "the time they took their frames, until Ctrl-C (files and cameras are not mixed).\n"
      "Writes into DIR: poses.jsonl (one line per frame set: per person the track id and the 15\n"
      "joints, metres, under joints_world in the rig's world), person_<id>.bvh per person (a "
      "humanoid skeleton with the person's bone\n"
      "lengths, y up, the floor at y = 0: the rig's floor, else the plane through its origin\n"
      "across the cameras' up axis, e.g. z = 0 for Pose2Sim), person_<id>.trc per person (the 15\n"
      "joints as markers, Y up as Pose2Sim writes them, for OpenSim) and summary.json. People seen "
      "by one\n"
      "camera only are dropped and counted. A view's unreadable frames are named and the others\n"
      "go on; views of different lengths go on with the views left (counted as missing).\n"
      "DIR holding an earlier run's output is refused unless --force (as without --calibration).");
  args.positional("VIEW",
                  "one per rig camera: OpenPose JSON folder, video file or image folder; or a "
                  "camera: /dev/videoN, rtsp:// URL, aravis:ID",
                  true)
      .option("calibration", "RIG",
              "the rig: Pose2Sim/anipose TOML or OpenCV YAML (docs/cameras.md)")
      .option("out", "DIR", "output folder (created)")
      .flag("force", "replace an earlier run's output in DIR")
      .option("fps", "N",
              "frame rate of OpenPose JSON and image folders (30 when absent), and the rate asked "
              "of cameras; videos and streams have their own",
              std::nullopt, Range::between(0.1, 1000.0))
      .option("detector", "NAME",
              "videos, image folders and cameras: how people are found: auto (" +
                  std::string(kFileDetector) + " for files, " + std::string(kLiveMultiviewDetector) +
                  " for cameras: one detector per view) or one of " + detector_names(),
              "auto")
      .option("fit", "auto|off|live|full",
              "skeleton fit on all views (constant bone lengths per person, smooth, feet above "
              "the floor): full in windows of 300 frames per person overlapping by 30 (written "
              "as each window is solved), live with a 3-frame lag (a new person's first 30 "
              "frames held for their bone lengths); auto: full for files, live for cameras",
              "auto")
      .option("db", "FILE",
              "pose database (the CMU train split, as without --calibration): the skeleton fit "
              "also takes each person's monocular retrieval from the view that sees them best as "
              "a prior of the bones that lack two good views for a run of frames "
              "(docs/multiview.md, \"The monocular prior\"); without it, no prior")
      .option("offsets", "auto|N,N,...",
              "views filmed without a common clock: per view the frames it is shifted by (its "
              "frame i shows the first view's frame i + N), or auto: estimated from the people "
              "in OpenPose JSON views (docs/cameras.md, \"Frame offsets\"); applied to the "
              "nearest frame",
              std::nullopt,
              [] {
                Range frames = Range::between(-1e6, 1e6);
                frames.list = true;
                return frames.or_word("auto");
              }())
      .option("set", "NODE.PARAM=VALUE",
              "override a node parameter of the graph (e.g. solve.volume=x0,y0,z0,x1,y1,z1)",
              std::nullopt, true)
      .flag("ignore-view-check",
            "go on when OpenPose JSON views look given in another order than the rig's cameras "
            "or made at another image size than their camera's (checked on their first frames "
            "with everybody in view; docs/multiview.md), with a warning instead of refusing")
      .flag("quiet", "do not print statistics");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("out")) throw InputError("--out", "required: the output folder");
  if (!args.has("calibration")) throw InputError("--calibration", "required: the rig file");
  const std::string rig_file = args.get("calibration");
  const fs::path out = args.get("out");
  std::string fit = args.get("fit");
  if (fit != "auto" && fit != "off" && fit != "live" && fit != "full")
    throw InputError("--fit", "expected auto, off, live or full, got '" + fit + "'");

  // Everything that can be checked before DIR is touched.
  const camera::Rig rig = camera::read_rig(rig_file);
  if (const std::string problem = camera::rig_problem(rig); !problem.empty())
    throw InputError(rig_file, problem);
  std::vector<View> views = match_views(rig, args.positionals(), rig_file);
  refuse_mixed_views(views);
  const bool live = views.front().kind == ViewKind::camera;
  if (fit == "auto") fit = live ? "live" : "full";  // files are fitted offline, cameras with a lag
  if (args.has("db")) {
    if (fit == "off")
      throw InputError("--db", "the monocular prior is part of the fit: not with --fit off");
    posedb::Database::open(args.get("db"));  // readable, before DIR is touched
  }
  std::string detector = args.get("detector");
  if (detector == "auto") detector = std::string(live ? kLiveMultiviewDetector : kFileDetector);
  if (live && args.has("offsets"))
    throw InputError("--offsets",
                     "cameras are joined by the time they took their frames: "
                     "--offsets is for files filmed without a common clock");
  std::vector<NamedPath> inputs = {{"--calibration", rig_file}};
  for (const View& v : views) inputs.push_back({"VIEW", v.path});
  refuse_output_over_inputs({"--out", out.string()}, inputs);
  for (const char* name : {"poses.jsonl", "summary.json"})
    refuse_output_over_inputs({"--out", (out / name).string()}, inputs);
  double fps = args.has("fps") ? args.number("fps") : 0.0;
  std::int64_t frames = 0;
  // Opening a GigE camera starts Aravis' threads, which outlive it: they must inherit the stop
  // signals blocked, as the graph's signal watcher wants every thread (graph/signals.hpp), or a
  // Ctrl-C reaching one of them would end the process without its files' last words.
  if (live) block_stop_signals();
  for (View& v : views) {
    if (v.kind == ViewKind::openpose_json)
      check_json_view(v, rig_file);
    else if (v.kind == ViewKind::camera)
      check_camera_view(v, rig_file, args);
    else
      check_video_view(v, rig_file, args);
    if (fps <= 0.0 && v.fps > 0.0) fps = v.fps;
    frames = std::max(frames, v.frames);
  }
  check_frame_rates(views);
  if (fps <= 0.0) fps = 30.0;
  if (args.has("offsets")) apply_offsets(views, rig, args);
  check_views_agree(views, args.has("ignore-view-check"));
  std::string floor_how;
  const GroundPlane floor = multiview::rig_floor(rig, &floor_how);
  // TRC files are Y-up (OpenSim): a world whose floor is level in x-y (Pose2Sim's, a board's) is
  // turned as Pose2Sim turns it; one already y-up is written as it is.
  const std::string trc_world_up = std::abs(floor.normal.y) > std::abs(floor.normal.z) ? "y" : "z";

  graph::load_plugins_from_environment();
  graph::GraphSpec spec = graph::parse_graph_text(
      graph_text(views, rig_file, out, fps, detector, trc_world_up, fit, args),
      "mocap reconstruct");
  graph::apply_overrides(spec, args.all("set"));
  check_detector_model(spec);
  const graph::ResolvedGraph resolved = graph::resolve(std::move(spec));
  graph::RunOptions options;
  options.single_process = true;
  check_ports_free(resolved, options);
  EarlierOutput earlier = EarlierOutput::prepare(out, args.has("force"));

  const auto started = std::chrono::steady_clock::now();
  ProgressBar bar(!args.has("quiet") && isatty(STDERR_FILENO) != 0);
  const ProgressCallback progress = [&](const graph::GraphStats& stats) {
    for (const auto& n : stats.nodes) {
      if (n.type == "sink.jsonl" && frames > 0)
        bar.update("reconstruct", static_cast<double>(n.in) / static_cast<double>(frames));
    }
  };
  const ReconstructRun run = run_reconstruct_graph(resolved, options, progress, bar, earlier, out,
                                                   args.has("quiet"), started);
  if (run.nothing_written) return *run.nothing_written;
  json summary = summarize_output(out / "poses.jsonl");
  summary["calibration"] = rig_file;
  json view_list = json::array();
  for (std::size_t i = 0; i < views.size(); ++i) {
    const View& v = views[i];
    json entry = {{"camera", v.camera->name},
                  {"path", v.path},
                  {"kind", kind_name(v)},
                  {"frames", v.frames},
                  {"offset", offsets_json(v)}};
    if (live) add_camera_state(entry, run.result.stats, "view_" + std::to_string(i));
    view_list.push_back(std::move(entry));
  }
  summary["views"] = view_list;
  summary["fps"] = fps;
  summary["floor"] = floor_how;
  summary["fit"] = fit;
  summary["prior_db"] = args.has("db") ? json(args.get("db")) : json(nullptr);
  return finish_reconstruct(run, summary, out, frames);
}

}  // namespace mocap::cli
