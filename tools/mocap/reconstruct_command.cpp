// `mocap reconstruct INPUT --db DB --out DIR`: runs the monocular graph on a folder of OpenPose
// JSON (graphs/monocular_json.yaml) or on a video, camera, stream or image folder
// (graphs/monocular_video.yaml: MoveNet finds the people) and writes poses.jsonl, one BVH per
// person, overlay.mp4 and summary.json.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "core/install_paths.hpp"
#include "core/keypoint_layout.hpp"
#include "core/messages.hpp"
#include "detect/model_files.hpp"
#include "detector_presets.hpp"
#include "eval_report.hpp"
#include "graph/graph_spec.hpp"
#include "graph/plugins.hpp"
#include "graph/validation.hpp"
#include "graph_runner.hpp"
#include "io/openpose_json.hpp"
#include "progress_bar.hpp"
#include "video/video_source.hpp"

namespace mocap::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string default_database() {
  return (install_root() / "build" / "db" / "cmu31_train.mdb").string();
}

// Points every node of the given type at the run's input, database and output folder, whatever
// the graph names its nodes.
void set_param(graph::GraphSpec& spec, std::string_view type, const std::string& param,
               const std::string& value) {
  for (auto& node : spec.nodes) {
    if (node.type == type) node.params[param] = {value, {"mocap reconstruct", 0}};
  }
}

// What the input is: a folder of OpenPose JSON, or anything source.video reads (a video file, a
// camera device, a stream URL, a folder of images).
enum class InputKind { openpose_json, video };

InputKind input_kind(const std::string& input) {
  std::error_code ec;
  if (fs::is_directory(input, ec)) {
    bool images = false;
    for (const auto& e : fs::directory_iterator(input, ec)) {
      const std::string name = e.path().filename().string();
      if (name.ends_with("_keypoints.json")) return InputKind::openpose_json;
      images = images || video::is_image_file_name(name);
    }
    if (images) return InputKind::video;
    throw InputError(input,
                     "neither OpenPose *_keypoints.json files nor images (.png, .jpg, ...) here");
  }
  if (video::classify(input) == video::SourceKind::file && !fs::exists(input, ec))
    throw InputError(input, "no such file or folder");
  return InputKind::video;
}

// The video's geometry and rate, read by opening it (closed again before the graph opens it).
struct VideoInfo {
  int width = 0, height = 0;
  double fps = 0.0;
  std::int64_t frames = -1;
  bool live = false;
};

VideoInfo probe_video(const Args& args) {
  video::SourceOptions options;
  if (args.has("fps")) options.folder_fps = std::stod(args.get("fps"));
  const video::VideoSource source(args.positionals()[0], options);
  return {source.width(), source.height(), source.fps(), source.frame_count(), source.live()};
}

std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// A file or image folder is read a second time by the overlay, by frame number as the 3D of each
// frame arrives (its video_path), instead of through an edge from the source: no decoded frame
// waits in the overlay for its 3D (a full fit sends it a window later), and the overlay never
// holds the source up. Cameras and streams cannot be read twice and keep the edge.
void read_frames_in_overlay(graph::GraphSpec& spec, const std::string& input) {
  set_param(spec, "sink.overlay", "video_path", input);
  std::erase_if(spec.edges, [&](const graph::EdgeSpec& edge) {
    const graph::NodeSpec* to = spec.find_node(edge.to.node);
    return to && to->type == "sink.overlay" && edge.to.port == "video";
  });
}

void configure_video(graph::GraphSpec& spec, const Args& args, const VideoInfo& info) {
  set_param(spec, "source.video", "path", args.positionals()[0]);
  set_param(spec, "source.video", "decoder_threads", args.get("decoder-threads"));
  if (args.has("fps")) set_param(spec, "source.video", "fps", args.get("fps"));
  if (args.has("detector-size")) {
    const bool multipose = std::any_of(spec.nodes.begin(), spec.nodes.end(),
                                       [](const auto& n) { return n.type == "detect.movenet"; });
    if (!multipose)
      throw InputError("--detector-size",
                       "sets the input size of the multipose detectors only; "
                       "add --detector multipose");
    set_param(spec, "detect.movenet", "input_size", args.get("detector-size"));
  }
  for (const auto& preset : detector_presets()) {
    set_param(spec, preset.type, "threads", args.get("detector-threads"));
    set_param(spec, preset.type, "backend", args.get("detector-backend"));
  }
  const double fps = args.has("fps") ? std::stod(args.get("fps")) : info.fps > 0 ? info.fps : 30.0;
  for (const char* type : {"sink.bvh", "sink.overlay"}) set_param(spec, type, "fps", number(fps));
  const std::string width = std::to_string(info.width), height = std::to_string(info.height);
  for (const char* type : {"recon.temporal_selector", "recon.fit"}) {
    set_param(spec, type, "image_width", width);
    set_param(spec, type, "image_height", height);
    set_param(spec, type, "hfov_deg", args.get("hfov"));
  }
  set_param(spec, "sink.overlay", "canvas_width", width);
  set_param(spec, "sink.overlay", "canvas_height", height);
  if (!info.live) read_frames_in_overlay(spec, args.positionals()[0]);
}

bool is_detector(const std::string& type) {
  for (const auto& preset : detector_presets())
    if (preset.type == type) return true;
  return false;
}

// Puts the named strategy in place of the graph's detector node (same name, same edges).
void choose_detector(graph::GraphSpec& spec, const std::string& name) {
  const DetectorPreset& preset = detector_preset(name);
  bool found = false;
  for (auto& node : spec.nodes) {
    if (!is_detector(node.type)) continue;
    node.type = preset.type;
    node.params.clear();
    for (const auto& [key, value] : preset.params)
      node.params[key] = {value, {"mocap reconstruct --detector", 0}};
    found = true;
  }
  if (!found) throw InputError("--detector", "the graph has no detector node to replace");
}

// A graph with detector nodes on the cached models: a missing model is reported before anything
// runs, naming the command that fetches it.
void check_detector_model(const graph::GraphSpec& spec) {
  const auto given = [](const graph::NodeSpec& node, const char* key) {
    const auto it = node.params.find(key);
    return it != node.params.end() && !it->second.text.empty();
  };
  for (const auto& node : spec.nodes) {
    if (node.type == "detect.movenet" || node.type == "detect.tiles") {
      if (!given(node, "model")) detect::movenet_model_json();
    } else if (node.type == "detect.topdown") {
      if (!given(node, "box_model_file")) detect::cached_model_json("centernet");
      if (!given(node, "pose_model_file")) {
        const auto it = node.params.find("pose_model");
        const bool thunder = it != node.params.end() && it->second.text == "thunder";
        detect::cached_model_json(thunder ? "movenet-thunder" : "movenet-lightning");
      }
    }
  }
}

// What --layout-offsets means for the matcher: auto names the input's layout (MoveNet's COCO-17
// for video; for OpenPose JSON, the layout of the folder's first file), whose file in
// calibration/layouts/ is then used; off and files pass through.
std::string matcher_layout_offsets(const std::string& setting, const std::string& input,
                                   InputKind kind) {
  if (setting != "auto") return setting;
  if (kind == InputKind::video) return std::string(layout(LayoutId::coco17).name);
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(input))
    if (e.path().filename().string().ends_with("_keypoints.json")) files.push_back(e.path());
  if (files.empty()) return "off";
  const People2D first = io::read_openpose_file(*std::min_element(files.begin(), files.end()));
  return std::string(layout(first.layout).name);
}

// What --fit means: auto fits the whole sequence of a file (offline), with a fixed lag for a live
// source, and not at all for keypoints whose camera is unknown (JSON without --image-size or
// --camera: nothing tells where the camera's rays go).
std::string fit_mode(const Args& args, InputKind kind, bool live) {
  const std::string fit = args.get("fit");
  if (fit != "auto" && fit != "off" && fit != "live" && fit != "full")
    throw InputError("--fit", "expected auto, off, live or full, got '" + fit + "'");
  const bool camera_known =
      kind == InputKind::video || args.has("image-size") || args.has("camera");
  if (fit == "auto") {
    if (!camera_known) {
      std::cerr << "mocap reconstruct: no skeleton fitting (no root translation): the keypoints' "
                   "image size is unknown; give --image-size WxH or --camera FILE\n";
      return "off";
    }
    return live ? "live" : "full";
  }
  if (fit != "off" && !camera_known)
    throw InputError("--fit", "fitting needs the camera: give --image-size WxH or --camera FILE");
  return fit;
}

void configure(graph::GraphSpec& spec, const Args& args, const fs::path& out, InputKind kind) {
  set_param(spec, "source.openpose_json", "path", args.positionals()[0]);
  const std::string fps = args.has("fps") ? args.get("fps") : "30";
  for (const char* type : {"source.openpose_json", "sink.bvh", "sink.overlay"})
    set_param(spec, type, "fps", fps);
  for (const char* type :
       {"recon.scaler", "recon.matcher", "recon.temporal_selector", "recon.fit", "sink.bvh"}) {
    set_param(spec, type, "db", args.get("db"));
  }
  set_param(spec, "recon.temporal_selector", "mode", args.get("mode"));
  set_param(spec, "recon.matcher", "layout_offsets",
            matcher_layout_offsets(args.get("layout-offsets"), args.positionals()[0], kind));
  if (args.has("image-size")) {
    const std::string size = args.get("image-size");
    const auto x = size.find('x');
    if (x == std::string::npos || x == 0 || x + 1 == size.size() ||
        size.find_first_not_of("0123456789x") != std::string::npos) {
      throw InputError("--image-size",
                       "expected WIDTHxHEIGHT in pixels, e.g. 1920x1080, got '" + size + "'");
    }
    for (const char* type : {"recon.temporal_selector", "recon.fit"}) {
      set_param(spec, type, "image_width", size.substr(0, x));
      set_param(spec, type, "image_height", size.substr(x + 1));
      set_param(spec, type, "hfov_deg", args.get("hfov"));
    }
  }
  if (args.has("camera")) {
    for (const char* type : {"recon.temporal_selector", "recon.fit"})
      set_param(spec, type, "camera", args.get("camera"));
  }
  set_param(spec, "sink.jsonl", "path", (out / "poses.jsonl").string());
  set_param(spec, "sink.bvh", "dir", out.string());
  set_param(spec, "sink.overlay", "video", (out / "overlay.mp4").string());
  set_param(spec, "sink.overlay", "png_dir", out.string());
}

// What the run produced, read back from poses.jsonl: frames, people, track lengths.
json summarize_output(const fs::path& jsonl) {
  std::ifstream in(jsonl);
  std::map<int, int> frames_per_id;
  std::size_t frames = 0, person_frames = 0, placed = 0;
  for (std::string line; std::getline(in, line);) {
    const json j = json::parse(line, nullptr, false);
    if (j.is_discarded()) continue;
    ++frames;
    for (const auto& p : j.value("people", json::array())) {
      ++frames_per_id[p.value("id", -1)];
      ++person_frames;
      placed += p.contains("joints_abs") ? 1 : 0;
    }
  }
  int long_tracks = 0;
  for (const auto& [id, n] : frames_per_id) long_tracks += n > 50 ? 1 : 0;
  return {{"frames", frames},
          {"people", frames_per_id.size()},
          {"person_frames", person_frames},
          {"placed_person_frames", placed},
          {"tracks_longer_than_50_frames", long_tracks}};
}

json node_latency(const graph::GraphStats& stats) {
  json nodes = json::object();
  for (const auto& n : stats.nodes) {
    nodes[n.node] = {{"type", n.type},   {"in", n.in},         {"out", n.out},
                     {"drops", n.drops}, {"p50_us", n.p50_us}, {"p95_us", n.p95_us}};
  }
  return nodes;
}

}  // namespace

int reconstruct_command(int argc, char** argv) {
  Args args(
      "mocap reconstruct INPUT --out DIR [--db DB] [options]",
      "Reconstructs the 3D motion of every person in a video file, camera device (/dev/videoN),\n"
      "RTSP/HTTP stream or folder of images (people found by MoveNet), or in a folder of OpenPose\n"
      "*_keypoints.json files (BODY_25, BODY_25B, COCO-18). Writes into DIR: poses.jsonl (one "
      "line\n"
      "per input frame: 15 joints per person, metres, camera coordinates, root-relative, and\n"
      "absolute under joints_abs once fitted), "
      "person_<id>.bvh per person, overlay.mp4 (the input beside the 3D skeletons) and "
      "summary.json.");
  args.positional("INPUT",
                  "video file, /dev/videoN, rtsp:// or http:// URL, image folder, or "
                  "folder of OpenPose *_keypoints.json files")
      .option("out", "DIR", "output folder (created)")
      .option("db", "FILE", "pose database", default_database())
      .option("fps", "N",
              "frame rate (OpenPose JSON and image folders: 30 when absent; videos: their own)")
      .option("detector", "NAME",
              "video: how people are found: auto (" + std::string(kFileDetector) + " for files, " +
                  std::string(kLiveDetector) +
                  " for cameras and streams; docs/detection-strategies.md) or one of " +
                  detector_names(),
              "auto")
      .option("detector-size", "N",
              "video, multipose detectors: MoveNet input size, a multiple of 32 (256 fast, "
              "384-512 for small people)")
      .option("detector-backend", "NAME",
              "video: network runtime of the detector: auto (XNNPACK when built in, else "
              "cv::dnn), xnnpack or opencv (docs/models.md)",
              "auto")
      .option("detector-threads", "N",
              "video: detector network threads (0: XNNPACK 1, cv::dnn OpenCV's default)", "0")
      .option("decoder-threads", "N",
              "video: FFmpeg decoding threads (0: one per core; needs OpenCV >= 4.7)", "0")
      .option("image-size", "WxH",
              "OpenPose JSON: size of the images the keypoints came from; turns each pose onto "
              "its camera ray (off when absent; videos: always on, their own size)")
      .option("hfov", "DEG", "horizontal field of view assumed with --image-size", "60")
      .option("camera", "FILE",
              "calibrated camera (OpenCV YAML from `mocap calibrate intrinsics`): its matrix and "
              "lens distortion replace --image-size/--hfov for the ray through each root")
      .option("fit", "auto|off|live|full",
              "skeleton fitting (root translation, the person's bones, feet on the floor): full "
              "over the whole sequence, live with a 3-frame lag; auto: full for files, live for "
              "cameras and streams, off for OpenPose JSON without --image-size/--camera",
              "auto")
      .option("ground", "auto|feet|off",
              "the floor for the fitting: auto takes the camera file's (`mocap calibrate "
              "ground`), else estimates it from the people's feet",
              "auto")
      .option("mode", "NAME",
              "temporal selection: path (Viterbi, lag 8), greedy (the paper) or nearest", "path")
      .option("layout-offsets", "auto|off|FILE",
              "compare the database's candidates in the input layout's own joint definition "
              "(auto: calibration/layouts/<layout>.yaml; docs/keypoint-layouts.md; about "
              "twice the matching time)",
              "off")
      .option("graph", "FILE",
              "graph to run (default: graphs/monocular_json.yaml for OpenPose JSON, "
              "graphs/monocular_video.yaml otherwise)")
      .option("set", "NODE.PARAM=VALUE", "override a node parameter of the graph", std::nullopt,
              true)
      .flag("quiet", "do not print statistics");
  int code = 0;
  if (!args.parse(argc, argv, code)) return code;
  if (!args.has("out")) throw InputError("--out", "required: the output folder");
  if (!fs::exists(args.get("db"))) {
    throw InputError(args.get("db"),
                     "no pose database here: build one with 'mocap db build "
                     "../shared/data/mocap/cmu31 --split train --out " +
                         args.get("db") + "'");
  }
  const InputKind kind = input_kind(args.positionals()[0]);
  const VideoInfo info = kind == InputKind::video ? probe_video(args) : VideoInfo{};
  const fs::path out = args.get("out");
  fs::create_directories(out);

  graph::load_plugins_from_environment();
  const std::string graph_file =
      args.has("graph")
          ? args.get("graph")
          : (install_root() / "graphs" /
             (kind == InputKind::video ? "monocular_video.yaml" : "monocular_json.yaml"))
                .string();
  graph::GraphSpec spec = graph::load_graph_file(graph_file);
  if (kind == InputKind::video) {
    // The default graph carries the file default; --graph keeps its own unless asked.
    const std::string detector = args.get("detector");
    if (detector != "auto")
      choose_detector(spec, detector);
    else if (info.live && !args.has("graph"))
      choose_detector(spec, std::string(kLiveDetector));
  }
  configure(spec, args, out, kind);
  if (kind == InputKind::video) configure_video(spec, args, info);
  const std::string fit = fit_mode(args, kind, info.live);
  set_param(spec, "recon.fit", "mode", fit);
  set_param(spec, "recon.fit", "ground", args.get("ground"));
  graph::apply_overrides(spec, args.all("set"));
  check_detector_model(spec);
  json detector_summary = json::object();
  for (const auto& node : spec.nodes) {
    if (!is_detector(node.type)) continue;
    detector_summary["type"] = node.type;
    for (const auto& [key, value] : node.params) detector_summary["params"][key] = value.text;
  }
  const graph::ResolvedGraph resolved = graph::resolve(std::move(spec));

  const auto started = std::chrono::steady_clock::now();
  graph::RunOptions options;
  options.single_process = true;
  ProgressBar bar(!args.has("quiet") && isatty(STDERR_FILENO) != 0);
  ProgressCallback progress;
  if (info.frames > 0) {
    progress = [&](const graph::GraphStats& stats) {
      for (const auto& n : stats.nodes) {
        if (n.type == "sink.jsonl")
          bar.update("reconstruct", static_cast<double>(n.in) / static_cast<double>(info.frames));
      }
    };
  }
  const graph::RunResult result = run_graph_here(resolved, options, "mocap reconstruct", progress);
  bar.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!args.has("quiet")) std::cerr << graph::format_stats_table(result.stats);

  json summary = summarize_output(out / "poses.jsonl");
  summary["input"] = args.positionals()[0];
  summary["database"] = args.get("db");
  summary["mode"] = args.get("mode");
  summary["fit"] = fit;
  summary["graph"] = graph_file;
  if (kind == InputKind::video) {
    summary["detector"] = detector_summary;
    summary["video"] = {
        {"width", info.width}, {"height", info.height}, {"fps", info.fps}, {"frames", info.frames}};
  }
  summary["seconds"] = seconds;
  summary["frames_per_second"] = seconds > 0 ? summary["frames"].get<double>() / seconds : 0.0;
  summary["id_switches"] =
      nullptr;  // needs ground-truth identities: see `mocap eval` and the tracker tests
  summary["nodes"] = node_latency(result.stats);
  summary["completed"] = result.ok && !result.stopped;
  summary["git_commit"] = git_commit();
  std::ofstream(out / "summary.json") << summary.dump(2) << "\n";

  std::cout << "wrote " << (out / "poses.jsonl").string() << ": " << summary["frames"]
            << " frames, " << summary["people"] << " people ("
            << summary["tracks_longer_than_50_frames"] << " tracks longer than 50 frames), "
            << std::fixed << std::setprecision(1) << summary["frames_per_second"].get<double>()
            << " frames/s\n";
  std::vector<std::string> written;
  for (const auto& e : fs::directory_iterator(out)) {
    if (e.path().extension() == ".bvh" || e.path().extension() == ".mp4")
      written.push_back(e.path().string());
  }
  std::sort(written.begin(), written.end(), [](const std::string& a, const std::string& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;  // person_2 before person_10
  });
  // Many people: the BVH files in one line, not one line each.
  std::size_t bvh = 0;
  for (const std::string& file : written) {
    if (written.size() > 8 && file.ends_with(".bvh")) {
      ++bvh;
    } else {
      std::cout << "wrote " << file << "\n";
    }
  }
  if (bvh > 0)
    std::cout << "wrote " << bvh
              << " BVH files, one per person: " << (out / "person_<id>.bvh").string() << "\n";
  std::cout << "wrote " << (out / "summary.json").string() << "\n";
  if (!result.ok) {
    std::cerr << "mocap reconstruct: " << result.error << "\n";
    return 1;
  }
  return result.stopped ? 130 : 0;
}

}  // namespace mocap::cli
