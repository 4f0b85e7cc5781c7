// `mocap reconstruct INPUT --db DB --out DIR`: runs the monocular graph on a folder of OpenPose
// JSON (graphs/monocular_json.yaml) or on a video, camera, stream or image folder
// (graphs/monocular_video.yaml: MoveNet finds the people) and writes poses.jsonl, one BVH per
// person, overlay.mp4 and summary.json.
//
// It never damages what it did not write: everything it can check (options, input, database,
// camera file, graph, ports) is checked before it touches DIR; a DIR holding an earlier run's
// output is refused unless --force, which removes that output first (reconstruct_outputs.hpp);
// the sinks create their files when their first frame arrives and write them in place as the run
// goes, so a killed run keeps them under their own names; summary.json is written last, through a
// temporary file, and lists the files of this run.

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

#include "camera/camera_file.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "core/install_paths.hpp"
#include "core/keypoint_layout.hpp"
#include "core/messages.hpp"
#include "detect/model_files.hpp"
#include "detect/singlepose.hpp"
#include "detector_presets.hpp"
#include "eval_report.hpp"
#include "graph/graph_spec.hpp"
#include "graph/plugins.hpp"
#include "graph/validation.hpp"
#include "graph_runner.hpp"
#include "input_kind.hpp"
#include "io/openpose_json.hpp"
#include "output_files.hpp"
#include "posedb/database.hpp"
#include "progress_bar.hpp"
#include "reconstruct_outputs.hpp"
#include "reconstruct_report.hpp"
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

std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
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
  if (args.has("fps")) options.folder_fps = options.fps = args.number("fps");
  const video::VideoSource source(args.positionals()[0], options);
  VideoInfo info{source.width(), source.height(), source.fps(), source.frame_count(),
                 source.live()};
  // A video file or stream has its own rate, which stamps poses.jsonl's times: another --fps would
  // make the BVH and the overlay disagree with them. Image folders and cameras take --fps.
  const bool own_rate =
      source.kind() == video::SourceKind::file || source.kind() == video::SourceKind::network;
  if (args.has("fps") && own_rate && info.fps > 0 &&
      std::abs(args.number("fps") - info.fps) > 1e-3 * info.fps) {
    throw InputError("--fps", "the video " + args.positionals()[0] + " runs at " +
                                  number(info.fps) +
                                  " frames/s, its own rate, which times "
                                  "every output; --fps " +
                                  args.get("fps") +
                                  " is for image folders, cameras and OpenPose JSON: leave it out "
                                  "(or resample the video, e.g. ffmpeg -i IN -r " +
                                  args.get("fps") + " OUT)");
  }
  return info;
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
  const double fps = info.fps > 0 ? info.fps : args.has("fps") ? args.number("fps") : 30.0;
  for (const char* type : {"sink.bvh", "sink.overlay"}) set_param(spec, type, "fps", number(fps));
  const std::string width = std::to_string(info.width), height = std::to_string(info.height);
  for (const char* type : {"recon.temporal_selector", "recon.fit"}) {
    set_param(spec, type, "image_width", width);
    set_param(spec, type, "image_height", height);
    set_param(spec, type, "hfov_deg", args.get("hfov"));
  }
  set_param(spec, "sink.overlay", "canvas_width", width);
  set_param(spec, "sink.overlay", "canvas_height", height);
  if (!info.live) {
    read_frames_in_overlay(spec, args.positionals()[0]);
    // A file waits for nobody: the top-down networks build the batch shapes they meet as they
    // meet them instead of every shape up front (measured in docs/detection-strategies.md,
    // "Both cores for the file default").
    set_param(spec, "detect.topdown", "warm_up", "false");
  }
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

// What --fit means: auto fits a file offline (full: overlapping windows), a live source with a
// fixed lag, and not at all keypoints whose camera is unknown (JSON without --image-size or
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
    const ImageSize size = args.image_size("image-size");
    for (const char* type : {"recon.temporal_selector", "recon.fit"}) {
      set_param(spec, type, "image_width", std::to_string(size.width));
      set_param(spec, type, "image_height", std::to_string(size.height));
      set_param(spec, type, "hfov_deg", args.get("hfov"));
    }
  }
  if (args.has("camera")) {
    for (const char* type : {"recon.temporal_selector", "recon.fit"})
      set_param(spec, type, "camera", args.get("camera"));
    // The messages name their camera as the camera file does (docs/cameras.md).
    const std::string name = camera::read_camera_file(args.get("camera")).name;
    for (const char* type : {"source.video", "source.openpose_json"})
      set_param(spec, type, "camera", name);
  }
  set_param(spec, "sink.jsonl", "path", (out / "poses.jsonl").string());
  set_param(spec, "sink.bvh", "dir", out.string());
  set_param(spec, "sink.overlay", "video", (out / "overlay.mp4").string());
  set_param(spec, "sink.overlay", "png_dir", out.string());
}

// The keypoints of an OpenPose folder must lie in the image the size says (`option` names it):
// a smaller size would put every ray and the fit's camera wrong. Files that cannot be read are
// left to the source, which reports them.
void check_keypoints_inside(const std::string& folder, int width, int height,
                            const std::string& option) {
  float max_x = 0.0f, max_y = 0.0f;
  fs::path at_x, at_y;
  for (const auto& e : fs::directory_iterator(folder)) {
    if (!e.path().filename().string().ends_with("_keypoints.json")) continue;
    People2D people;
    try {
      people = io::read_openpose_file(e.path());
    } catch (const std::exception&) {
      continue;
    }
    for (const Person2D& p : people.people) {
      for (const Keypoint2D& k : p.joints) {
        if (!(k.confidence > 0.0f) || !std::isfinite(k.x) || !std::isfinite(k.y)) continue;
        if (k.x > max_x) max_x = k.x, at_x = e.path();
        if (k.y > max_y) max_y = k.y, at_y = e.path();
      }
    }
  }
  // Keypoints may sit on the last pixel's far edge: a pixel of slack.
  if (max_x > static_cast<float>(width) + 1.0f || max_y > static_cast<float>(height) + 1.0f) {
    const bool x = max_x > static_cast<float>(width) + 1.0f;
    throw InputError(option, std::to_string(width) + "x" + std::to_string(height) +
                                 " is smaller than the keypoints: " + (x ? "x" : "y") +
                                 " reaches " + number(x ? max_x : max_y) + " in " +
                                 (x ? at_x : at_y).string() +
                                 "; give the size of the images the keypoints came from");
  }
}

// The database and camera file are read now, before DIR is touched: a missing, damaged (checksums)
// or foreign file ends the command with nothing written.
void check_database_and_camera(const Args& args) {
  const std::string db = args.get("db");
  if (!fs::exists(db)) {
    throw InputError(db,
                     "no pose database here: build one with 'mocap db build "
                     "../shared/data/mocap/cmu31 --split train --out " +
                         db + "'");
  }
  (void)posedb::Database::open(db);
  if (args.has("camera")) (void)camera::read_camera_file(args.get("camera"));
}

// No output may be an input: DIR is not the input, and none of the files written into it is the
// input, the database, the camera file or the graph.
void refuse_outputs_over_inputs(const Args& args, const fs::path& out,
                                const std::string& graph_file) {
  const std::vector<NamedPath> inputs = {{"INPUT", args.positionals()[0]},
                                         {"--db", args.get("db")},
                                         {"--camera", args.get("camera")},
                                         {"--graph", graph_file}};
  refuse_output_over_inputs({"--out", out.string()}, {inputs[0]});
  for (const char* name : {"poses.jsonl", "summary.json", "overlay.mp4"})
    refuse_output_over_inputs({"--out", (out / name).string()}, inputs);
}

}  // namespace

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
        // An unknown name is left to the node, whose error lists the accepted ones.
        try {
          detect::cached_model_json(detect::model_name(
              detect::parse_pose_model(it != node.params.end() ? it->second.text : "lightning")));
        } catch (const std::invalid_argument&) {
        }
      }
    }
  }
}

// What the run produced, read back from poses.jsonl: frames, people, track lengths. Only whole
// lines count: a last line without its newline was cut by a kill.
json summarize_output(const fs::path& jsonl) {
  std::ifstream in(jsonl, std::ios::binary);
  std::map<int, int> frames_per_id;
  std::size_t frames = 0, person_frames = 0, placed = 0;
  for (std::string line; std::getline(in, line);) {
    if (in.eof()) break;  // no newline after it
    const json j = json::parse(line, nullptr, false);
    if (j.is_discarded()) continue;
    ++frames;
    for (const auto& p : j.value("people", json::array())) {
      ++frames_per_id[p.value("id", -1)];
      ++person_frames;
      placed += p.contains("joints_abs") || p.contains("joints_world") ? 1 : 0;
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

json files_json(const std::vector<fs::path>& files) {
  json list = json::array();
  for (const fs::path& file : files) {
    std::error_code ec;
    const auto bytes = fs::file_size(file, ec);
    list.push_back({{"path", file.string()}, {"bytes", ec ? 0 : bytes}});
  }
  return list;
}

// "wrote ..." lines for the files of this run (all the outputs in DIR: see
// reconstruct_outputs.hpp).
void print_written(const fs::path& out, const WrittenOutputs& written, const json& summary,
                   double frames_per_second) {
  for (const fs::path& file : written.poses) {
    std::cout << "wrote " << file.string() << ": " << summary["frames"] << " frames, "
              << summary["people"] << " people (" << summary["tracks_longer_than_50_frames"]
              << " tracks longer than 50 frames), " << std::fixed << std::setprecision(1)
              << frames_per_second << " frames/s\n";
  }
  if (written.bvh.size() > 8) {
    std::cout << "wrote " << written.bvh.size()
              << " BVH files, one per person: " << (out / "person_<id>.bvh").string() << " (ids";
    for (std::size_t i = 0; i < written.bvh_ids.size(); ++i)
      std::cout << (i ? ", " : " ") << written.bvh_ids[i];
    std::cout << ")\n";
  } else {
    for (const fs::path& file : written.bvh) std::cout << "wrote " << file.string() << "\n";
  }
  for (const fs::path& file : written.videos) std::cout << "wrote " << file.string() << "\n";
  if (written.images.size() > 2) {
    std::cout << "wrote " << written.images.size()
              << " overlay images: " << (out / "overlay_<frame>.png").string() << "\n";
  } else {
    for (const fs::path& file : written.images) std::cout << "wrote " << file.string() << "\n";
  }
}

// For a run that did not complete but wrote something: what it kept, and what it did not write.
std::string incomplete_note(const WrittenOutputs& written, const json& summary,
                            std::int64_t input_frames) {
  std::ostringstream note;
  note << "kept what it wrote before it ended (the files above, each whole): poses.jsonl holds "
       << summary["frames"].get<std::size_t>() << " frames";
  if (input_frames > 0) note << " of the " << input_frames << " the input announced";
  std::vector<std::string> missing;
  if (written.poses.empty()) missing.push_back("poses.jsonl");
  if (written.bvh.empty()) missing.push_back("any person_<id>.bvh");
  if (written.videos.empty()) missing.push_back("overlay.mp4");
  for (std::size_t i = 0; i < missing.size(); ++i)
    note << (i ? ", " : "; not written: ") << missing[i];
  if (!written.partial.empty()) note << "; left incomplete: " << short_list(written.partial);
  return note.str();
}

ReconstructRun run_reconstruct_graph(const graph::ResolvedGraph& graph,
                                     const graph::RunOptions& options,
                                     const ProgressCallback& progress, ProgressBar& bar,
                                     EarlierOutput& earlier, const fs::path& out, bool quiet,
                                     std::chrono::steady_clock::time_point started) {
  ReconstructRun run;
  try {
    run.result = run_graph_here(graph, options, "mocap reconstruct", progress);
  } catch (...) {
    std::vector<fs::path> files = reconstruct_outputs_in(out);
    std::erase_if(files, [](const fs::path& f) { return f.filename() == "summary.json"; });
    earlier.settle(!files.empty());
    throw;
  }
  bar.finish();
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!quiet) std::cerr << graph::format_stats_table(run.result.stats);
  run.files = reconstruct_outputs_in(out);
  std::erase_if(run.files, [](const fs::path& f) { return f.filename() == "summary.json"; });
  run.written = classify_outputs(run.files);
  const bool wrote_output = !run.files.empty();
  const bool earlier_put_back = earlier.count() > 0 && !wrote_output;
  if (const std::string note = earlier.settle(wrote_output); !note.empty())
    std::cerr << "mocap reconstruct: " << note << "\n";
  const graph::RunResult& r = run.result;
  run.outcome = !r.ok ? "failed: " + r.error : r.stopped ? std::string("interrupted") : "";
  if (earlier_put_back || (!wrote_output && !run.outcome.empty())) {
    if (!run.outcome.empty()) std::cerr << "mocap reconstruct: " << run.outcome << "\n";
    std::cerr << "mocap reconstruct: nothing was written into " << out.string() << "\n";
    run.nothing_written = !r.ok ? 1 : r.stopped ? 130 : 0;
  }
  return run;
}

json node_latency(const graph::GraphStats& stats) {
  json nodes = json::object();
  for (const auto& n : stats.nodes) {
    nodes[n.node] = {{"type", n.type},   {"in", n.in},         {"out", n.out},
                     {"drops", n.drops}, {"p50_us", n.p50_us}, {"p95_us", n.p95_us}};
    // Its last status line (the fits: what was fitted and the time per frame or frame set).
    if (!n.status.empty()) nodes[n.node]["status"] = n.status;
    if (n.sync.inputs.empty()) continue;
    // A joined node: its sets, and the messages that came after their set went on.
    std::uint64_t late = 0, late_dropped = 0;
    for (const auto& input : n.sync.inputs) late += input.late, late_dropped += input.late_dropped;
    nodes[n.node]["sync"] = {{"sets", n.sync.sets},
                             {"complete", n.sync.complete},
                             {"late", late},
                             {"late_dropped", late_dropped}};
  }
  return nodes;
}

int reconstruct_command(int argc, char** argv) {
  if (asks_for_multiview(argc, argv)) return reconstruct_multiview_command(argc, argv);
  Args args(
      "mocap reconstruct INPUT --out DIR [--db DB] [--force] [options]",
      "Reconstructs the 3D motion of every person in a video file, camera device (/dev/videoN),\n"
      "RTSP/HTTP stream or folder of images (people found by MoveNet), or in a folder of OpenPose\n"
      "*_keypoints.json files (BODY_25, BODY_25B, COCO-18). Writes into DIR: poses.jsonl (one "
      "line\n"
      "per input frame: 15 joints per person, metres, camera coordinates, root-relative, and\n"
      "absolute under joints_abs once fitted), person_<id>.bvh per person (root placed once\n"
      "fitted), overlay.mp4 (the input beside the 3D skeletons) and summary.json (what was run\n"
      "and the files it wrote).\n\n"
      "DIR holding an earlier run's output (poses.jsonl, summary.json, person_*.bvh, overlay*) is\n"
      "refused, naming what is there, unless --force: then those files (only those) are set aside\n"
      "once the input, database, camera file and graph have been checked, removed when the run "
      "has\n"
      "written its output, put back as they were when it wrote none (it failed at the start).\n"
      "Files are written as the run goes and stay whole, so an interrupted run (Ctrl-C, a kill)\n"
      "keeps what it wrote under the files' own names; summary.json is written at the end.\n\n"
      "Several calibrated cameras: mocap reconstruct --calibration RIG VIEW1 VIEW2 ... --out DIR\n"
      "(see mocap reconstruct --calibration RIG --help).");
  args.positional("INPUT",
                  "video file, /dev/videoN, rtsp:// or http:// URL, image folder, or "
                  "folder of OpenPose *_keypoints.json files")
      .option("out", "DIR", "output folder (created)")
      .flag("force", "replace an earlier run's output in DIR (see above)")
      .option("db", "FILE", "pose database", default_database())
      .option("fps", "N",
              "frame rate of image folders and OpenPose JSON (30 when absent), and the rate asked "
              "of a camera; every output uses it. A video file or stream has its own rate: "
              "another --fps is refused",
              std::nullopt, Range::between(0.1, 1000.0))
      .option("detector", "NAME",
              "video: how people are found: auto (" + std::string(kFileDetector) + " for files, " +
                  std::string(kLiveDetector) +
                  " for cameras and streams; docs/detection-strategies.md) or one of " +
                  detector_names(),
              "auto")
      .option("detector-size", "N",
              "video, multipose detectors: MoveNet input size, a multiple of 32 (256 fast, "
              "384-512 for small people)",
              std::nullopt, Range::count(128, 1024))
      .option("detector-backend", "NAME",
              "video: network runtime of the detector: auto (XNNPACK when built in, else "
              "cv::dnn), xnnpack or opencv (docs/models.md)",
              "auto")
      .option("detector-threads", "N",
              "video: detector network threads (0: XNNPACK 1, cv::dnn OpenCV's default)", "0",
              Range::count(0, 64))
      .option("decoder-threads", "N",
              "video: FFmpeg decoding threads (0: one per core; needs OpenCV >= 4.7)", "0",
              Range::count(0, 64))
      .option("image-size", "WxH",
              "OpenPose JSON: size of the images the keypoints came from (refused when smaller "
              "than the keypoints); turns each pose onto its camera ray (off when absent; "
              "videos: always on, their own size)",
              std::nullopt, Range::image_size())
      .option("hfov", "DEG", "horizontal field of view assumed with --image-size", "60",
              Range::between(1.0, 179.0))
      .option("camera", "FILE",
              "calibrated camera: the OpenCV YAML of `mocap calibrate intrinsics` or any rig "
              "file of one camera (docs/cameras.md); its matrix and lens distortion replace "
              "--image-size/--hfov for the ray through each root")
      .option("fit", "auto|off|live|full",
              "skeleton fitting (root translation, the person's bones, feet on the floor): full "
              "in windows of 64 frames per person overlapping by 16 (written as each window is "
              "solved), live with a 3-frame lag; auto: full for files, live for cameras and "
              "streams, off for OpenPose JSON without --image-size/--camera",
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
  if (args.has("detector-size") && args.integer("detector-size") % 32 != 0)
    throw InputError("--detector-size",
                     "expected a multiple of 32, got " + args.get("detector-size"));
  const std::string input = args.positionals()[0];
  const fs::path out = args.get("out");

  // Everything that can be checked before DIR is touched.
  // A camera (device, stream) is read by source.video like a file: the graph is the same.
  const InputKind given = input_kind(input);
  const InputKind kind = given == InputKind::camera ? InputKind::video : given;
  refuse_output_over_inputs({"--out", out.string()}, {{"INPUT", input}});
  check_database_and_camera(args);
  const VideoInfo info = kind == InputKind::video ? probe_video(args) : VideoInfo{};
  if (kind == InputKind::openpose_json) {
    if (args.has("camera")) {
      const camera::Camera lens = camera::read_camera_file(args.get("camera"));
      check_keypoints_inside(input, lens.width, lens.height, args.get("camera"));
    } else if (args.has("image-size")) {
      const ImageSize size = args.image_size("image-size");
      check_keypoints_inside(input, size.width, size.height, "--image-size");
    }
  }
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
    if (detector != "auto") choose_detector(spec, detector);
    if (info.live && !args.has("graph")) {
      if (detector == "auto") choose_detector(spec, std::string(kLiveDetector));
      // Live: each frame decided as it comes; a look-ahead would cost lag x the detector's period.
      set_param(spec, "recon.temporal_selector", "lag", "0");
    }
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
  refuse_outputs_over_inputs(args, out, graph_file);
  graph::RunOptions options;
  options.single_process = true;
  check_ports_free(resolved, options);
  EarlierOutput earlier = EarlierOutput::prepare(out, args.has("force"));

  const auto started = std::chrono::steady_clock::now();
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
  const ReconstructRun run = run_reconstruct_graph(resolved, options, progress, bar, earlier, out,
                                                   args.has("quiet"), started);
  if (run.nothing_written) return *run.nothing_written;
  json summary = summarize_output(out / "poses.jsonl");
  summary["input"] = input;
  summary["database"] = args.get("db");
  summary["mode"] = args.get("mode");
  summary["fit"] = fit;
  summary["graph"] = graph_file;
  if (kind == InputKind::video) {
    summary["detector"] = detector_summary;
    if (args.has("detector-size")) summary["detector_size"] = args.integer("detector-size");
    summary["video"] = {
        {"width", info.width}, {"height", info.height}, {"fps", info.fps}, {"frames", info.frames}};
  }
  summary["id_switches"] =
      nullptr;  // needs ground-truth identities: see `mocap eval` and the tracker tests
  return finish_reconstruct(run, summary, out, info.frames);
}

int finish_reconstruct(const ReconstructRun& run, json& summary, const fs::path& out,
                       std::int64_t input_frames) {
  const graph::RunResult& result = run.result;
  summary["seconds"] = run.seconds;
  const double frames_per_second =
      run.seconds > 0 ? summary["frames"].get<double>() / run.seconds : 0.0;
  summary["frames_per_second"] = frames_per_second;
  summary["nodes"] = node_latency(result.stats);
  summary["completed"] = result.ok && !result.stopped;
  summary["interrupted"] = result.stopped;
  if (!result.ok) summary["error"] = result.error;
  summary["files"] = files_json(run.files);
  summary["git_commit"] = git_commit();
  const fs::path summary_file = out / "summary.json";
  write_file_atomically(summary_file, json_text(summary, 2) + "\n");

  print_written(out, run.written, summary, frames_per_second);
  std::cout << "wrote " << summary_file.string() << "\n";
  if (!run.outcome.empty()) {
    std::cerr << "mocap reconstruct: " << run.outcome << "\n"
              << "mocap reconstruct: " << incomplete_note(run.written, summary, input_frames)
              << "\n";
  }
  if (!result.ok) return 1;
  return result.stopped ? 130 : 0;
}

}  // namespace mocap::cli
