// mocap-bench-video: the whole method on real videos, end to end (decode -> detector -> tracker ->
// scaler -> matcher -> temporal selection -> smoothing -> JSONL, BVH and overlay MP4), per video
// and detection strategy (mocap reconstruct --detector names; multipose ones per input size) x
// network runtime x workers (detect.movenet, detect.topdown) x threads, in
// two runs each:
//  * offline: every frame, as fast as possible (the graph of `mocap reconstruct VIDEO`):
//    frames per second, people per frame, tracks longer than 50 frames, id breaks and jumps;
//  * live: the file replayed at its own rate like a camera, the detector on a `latest` edge and
//    the 1-Euro smoother (graphs/live_webcam.yaml): latency from capture time to 3D output
//    (p50/p95), frames the detector kept up with, drops; the selector's look-ahead is --live-lag
//    (0 by default: each frame of look-ahead costs a detector period of latency).
// Prints Markdown tables. A probe node in this program records what reaches the outputs.

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <vector>

#include "cli_args.hpp"
#include "detector_presets.hpp"
#include "graph/graph_spec.hpp"
#include "graph/registry.hpp"
#include "graph/runtime.hpp"
#include "graph/transport.hpp"
#include "graph/validation.hpp"
#include "video/video_source.hpp"

namespace mocap::bench {
namespace {

using namespace mocap::graph;
namespace fs = std::filesystem;

// bench.probe: one line per message it receives, written to `path` as it goes:
//   "2 <frame> <id> <box centre x> <box centre y> <box height> ..." for the tracked 2D people,
//   "3 <frame> <capture_ns> <received_ns> <people>" for the 3D output.
class Probe : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("benchmark probe: records tracked 2D people and 3D output arrival times");
    c.input<People2D>("people2d");
    c.input<People3D>("people3d");
    c.required_param<std::string>("path", "file the records go to");
  }
  void open(Context& ctx) override {
    out_.open(ctx.param<std::string>("path"));
    if (!out_) throw std::runtime_error("cannot write " + ctx.param<std::string>("path"));
  }
  void process(Context& ctx) override {
    if (ctx.has("people3d")) {
      const People3D& p = ctx.input<People3D>("people3d");
      out_ << "3 " << p.header.frame << " " << p.header.capture_ns << " " << realtime_ns() << " "
           << p.people.size() << "\n";
    } else {
      const People2D& p = ctx.input<People2D>("people2d");
      out_ << "2 " << p.header.frame;
      for (const Person2D& person : p.people) {
        out_ << " " << person.id << " " << person.box.x + person.box.width / 2 << " "
             << person.box.y + person.box.height / 2 << " " << person.box.height;
      }
      out_ << "\n";
    }
  }
  void close(Context&) override { out_.close(); }

 private:
  std::ofstream out_;
};
MOCAP_REGISTER_NODE("bench.probe", Probe)

struct Box {
  float x = 0, y = 0, h = 0;
};

struct Records {
  std::map<std::int64_t, std::map<int, Box>> people2d;  // frame -> id -> box
  std::vector<std::int64_t> latency_ns;
  std::vector<std::int64_t> received_ns;
  std::vector<std::size_t> people3d;
};

Records read_records(const std::string& path) {
  Records r;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    std::istringstream s(line);
    int kind = 0;
    std::int64_t frame = 0;
    s >> kind >> frame;
    if (kind == 3) {
      std::int64_t capture = 0, received = 0;
      std::size_t people = 0;
      s >> capture >> received >> people;
      r.latency_ns.push_back(received - capture);
      r.received_ns.push_back(received);
      r.people3d.push_back(people);
    } else {
      auto& frame_people = r.people2d[frame];
      int id = 0;
      Box b;
      while (s >> id >> b.x >> b.y >> b.h) frame_people[id] = b;
    }
  }
  return r;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::lround(q * static_cast<double>(v.size() - 1)))];
}

// Tracking quality without ground truth, from the tracked boxes:
//  * breaks: a new id appears within 15 frames of a track's end, within half a body height of
//    where that track was last seen (one person, two ids);
//  * jumps: a track's box moves more than one body height between consecutive frames it is
//    seen in (the id went over to someone else).
struct TrackQuality {
  int tracks = 0, long_tracks = 0, breaks = 0, jumps = 0;
};

TrackQuality track_quality(const Records& r) {
  struct Track {
    std::int64_t first = 0, last = 0, frames = 0;
    Box first_box, last_box;
  };
  std::map<int, Track> tracks;
  TrackQuality q;
  for (const auto& [frame, people] : r.people2d) {
    for (const auto& [id, box] : people) {
      if (id < 0) continue;
      auto [it, fresh] = tracks.try_emplace(id);
      Track& t = it->second;
      if (fresh) {
        t.first = frame;
        t.first_box = box;
      } else {
        const float h = std::max(t.last_box.h, box.h);
        if (std::hypot(box.x - t.last_box.x, box.y - t.last_box.y) > h) ++q.jumps;
      }
      t.last = frame;
      t.last_box = box;
      ++t.frames;
    }
  }
  for (const auto& [id, t] : tracks) {
    ++q.tracks;
    if (t.frames > 50) ++q.long_tracks;
    for (const auto& [other_id, o] : tracks) {
      if (other_id == id || o.first <= t.last || o.first > t.last + 15) continue;
      const float h = std::max(t.last_box.h, o.first_box.h);
      if (std::hypot(o.first_box.x - t.last_box.x, o.first_box.y - t.last_box.y) < 0.5f * h) {
        ++q.breaks;
        break;
      }
    }
  }
  return q;
}

struct RunSpec {
  std::string video, db, out_dir;
  std::string detector = "multipose";  // a preset of tools/mocap/detector_presets.hpp
  int size = 256;                      // its input size when it is a multipose one
  bool live = false;
  int detector_threads = 0;
  std::string backend = "auto";
  int workers = 1;
  int lag = 8;
  bool print_stats = false;  // the runtime's per-node table (queues, waits) to stderr
  double replay_fps = 0;     // live runs: the file paced at this rate (0: its own)
};

std::string detector_node(const RunSpec& s) {
  const cli::DetectorPreset& preset = cli::detector_preset(s.detector);
  std::ostringstream node;
  node << "{ type: " << preset.type << ", params: { threads: " << s.detector_threads
       << ", backend: " << s.backend;
  // Copies of the network: on consecutive frames (detect.movenet) or sharing a frame's crops
  // (detect.topdown); the tiles have none.
  if (preset.type != "detect.tiles") node << ", workers: " << s.workers;
  for (const auto& [key, value] : preset.params)
    if (key != "workers")
      node << ", " << key << ": " << (key == "input_size" ? std::to_string(s.size) : value);
  node << " } }";
  return node.str();
}

std::string graph_text(const RunSpec& s, const video::VideoSource& info, const std::string& probe) {
  const double fps = info.fps() > 0 ? info.fps() : 30.0;
  std::ostringstream g;
  g << "graph: bench_video\nnodes:\n"
    << "  src: { type: source.video, params: { path: \"" << s.video
    << "\", mode: " << (s.live ? "live" : "offline")
    << (s.live && s.replay_fps > 0 ? ", replay_fps: " + std::to_string(s.replay_fps) : "")
    << " } }\n"
    << "  det: " << detector_node(s) << "\n"
    << "  track: { type: recon.tracker }\n"
    << "  scale: { type: recon.scaler, params: { db: \"" << s.db << "\" } }\n"
    << "  match: { type: recon.matcher, params: { db: \"" << s.db << "\", k: 32, probe: 16 } }\n"
    << "  select: { type: recon.temporal_selector, params: { db: \"" << s.db
    << "\", mode: path, lag: " << s.lag << ", image_width: " << info.width()
    << ", image_height: " << info.height() << " } }\n"
    << (s.live ? "  smooth: { type: recon.smooth_1euro, params: { beta: 0.4, min_cutoff: 1.0 } }\n"
               : "  smooth: { type: recon.smooth_savgol, params: { order: 3, window: 11 } }\n")
    << "  jsonl: { type: sink.jsonl, params: { path: \"" << s.out_dir << "/poses.jsonl\" } }\n"
    << "  bvh: { type: sink.bvh, params: { dir: \"" << s.out_dir << "\", db: \"" << s.db
    << "\", fps: " << fps << " } }\n"
    << "  overlay: { type: sink.overlay, params: { video: \"" << s.out_dir
    << "/overlay.mp4\", fps: " << fps << ", canvas_width: " << info.width()
    << ", canvas_height: " << info.height() << " } }\n"
    << "  probe: { type: bench.probe, params: { path: \"" << probe << "\" } }\n"
    << "edges:\n"
    << "  - [src.frames, det.in" << (s.live ? ", { policy: latest }" : "") << "]\n"
    << "  - [det.out, track.in]\n  - [track.out, scale.in]\n  - [scale.out, match.in]\n"
    << "  - [match.out, select.in]\n  - [select.out, smooth.in]\n  - [smooth.out, jsonl.in]\n"
    << "  - [smooth.out, bvh.in]\n"
    << "  - [src.frames, overlay.video" << (s.live ? ", { policy: \"drop_oldest(32)\" }" : "")
    << "]\n"
    << "  - [track.out, overlay.people2d]\n  - [smooth.out, overlay.people3d]\n"
    << "  - [track.out, probe.people2d]\n  - [smooth.out, probe.people3d]\n";
  return g.str();
}

struct Result {
  std::int64_t frames = 0;     // frames of the video
  std::int64_t outputs = 0;    // 3D outputs (frames the detector processed)
  double wall_s = 0, fps = 0;  // whole run; steady rate between the first and last output
  double people_mean = 0;      // tracked 2D people per processed frame
  std::size_t people_max = 0;
  double people3d_mean = 0;
  TrackQuality quality;
  double latency_p50_ms = 0, latency_p95_ms = 0;
  double latency_first_ms = 0, latency_last_ms = 0;  // p50 of the first and last quarter
  std::uint64_t source_skips = 0, detector_drops = 0;
  double det_p50_ms = 0;
};

Result run(const RunSpec& s) {
  const video::VideoSource info(s.video);
  fs::create_directories(s.out_dir);
  const std::string probe = s.out_dir + "/probe.txt";
  const auto started = std::chrono::steady_clock::now();
  RunOptions options;
  options.single_process = true;
  Runtime runtime(resolve(parse_graph_text(graph_text(s, info, probe), "bench_video.yaml")),
                  options);
  const RunResult result = runtime.run();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!result.ok) throw std::runtime_error(result.error);
  if (s.print_stats) {
    std::cerr << s.out_dir << ":\n" << format_stats_table(result.stats);
  }
  const Records r = read_records(probe);
  Result out;
  out.frames = info.frame_count();
  out.outputs = static_cast<std::int64_t>(r.received_ns.size());
  out.wall_s = wall;
  if (r.received_ns.size() > 1) {
    out.fps = static_cast<double>(r.received_ns.size() - 1) /
              (static_cast<double>(r.received_ns.back() - r.received_ns.front()) * 1e-9);
  }
  std::size_t people = 0;
  for (const auto& [frame, p] : r.people2d) {
    people += p.size();
    out.people_max = std::max(out.people_max, p.size());
  }
  if (!r.people2d.empty())
    out.people_mean = static_cast<double>(people) / static_cast<double>(r.people2d.size());
  std::size_t people3d = 0;
  for (std::size_t n : r.people3d) people3d += n;
  if (!r.people3d.empty())
    out.people3d_mean = static_cast<double>(people3d) / static_cast<double>(r.people3d.size());
  out.quality = track_quality(r);
  std::vector<double> latency;
  for (std::int64_t ns : r.latency_ns) latency.push_back(static_cast<double>(ns) * 1e-6);
  out.latency_p50_ms = percentile(latency, 0.5);
  out.latency_p95_ms = percentile(latency, 0.95);
  const std::size_t quarter = latency.size() / 4;
  out.latency_first_ms = percentile({latency.begin(), latency.begin() + quarter}, 0.5);
  out.latency_last_ms = percentile({latency.end() - quarter, latency.end()}, 0.5);
  for (const NodeStats& n : result.stats.nodes) {
    if (n.node == "src") out.source_skips = n.drops;
    if (n.node == "det") {
      out.detector_drops = n.drops;
      out.det_p50_ms = n.p50_us / 1000.0;
    }
  }
  return out;
}

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream s(list);
  for (std::string item; std::getline(s, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

// Every runtime x workers x threads x mode of the options, in that order.
std::vector<std::array<std::string, 4>> matrix(const cli::Args& args) {
  std::vector<std::array<std::string, 4>> out;
  for (const std::string& backend : split(args.get("backends")))
    for (const std::string& workers : split(args.get("workers")))
      for (const std::string& threads : split(args.get("threads")))
        for (const std::string& mode : split(args.get("modes")))
          out.push_back({backend, workers, threads, mode});
  return out;
}

}  // namespace
}  // namespace mocap::bench

int main(int argc, char** argv) {
  using namespace mocap;
  using namespace mocap::bench;
  cli::Args args("mocap-bench-video --videos LIST [options]",
                 "End-to-end speed, latency and tracking on real videos (Markdown tables).");
  args.option("videos", "LIST", "comma-separated video files",
              "/usr/share/doc/opencv-doc/examples/data/vtest.avi,"
              "../shared/data/eval/openpose_examples_media/video.avi")
      .option("detectors", "LIST",
              "detection strategies (mocap reconstruct --detector names: " + cli::detector_names() +
                  ")",
              "multipose")
      .option("sizes", "LIST", "MoveNet input sizes of the multipose detectors", "256,384")
      .option("db", "FILE", "pose database", "build/db/cmu31_train.mdb")
      .option("modes", "LIST", "offline, live or both", "offline,live")
      .option("threads", "LIST", "detector threads per worker (0: the runtime's default)", "0")
      .option("backends", "LIST", "detector runtimes: auto, xnnpack, opencv", "auto")
      .option("workers", "LIST",
              "detector workers (network copies: on consecutive frames for multipose, sharing a "
              "frame's crops for topdown; not tiles)",
              "1")
      .option("lag", "N", "temporal selection look-ahead in frames, offline runs", "8")
      .option("live-lag", "N",
              "the same for live runs: it holds each frame until N more have been detected, i.e. "
              "N x the detector's period (docs/detection-strategies.md, 2026-11-26)",
              "0")
      .option("replay-fps", "F",
              "live runs: the file replayed at F frames/s instead of its own rate (a 10 fps clip "
              "as a 25 fps camera); 0: its own",
              "0")
      .flag("stats",
            "print each run's per-node statistics to stderr (queue depth, how long messages "
            "waited in each node's inputs, time blocked on a full queue downstream)")
      .option("out", "DIR", "where each run's outputs go", "/tmp/mocap-bench-video");
  int exit_code = 0;
  if (!args.parse(argc - 1, argv + 1, exit_code)) return exit_code;
  try {
    std::cout
        << "| video | detector | runtime | workers | threads | mode | frames | 3D outputs | "
           "wall s | fps | people/frame (max) "
           "| 3D people/frame | tracks | tracks > 50 | id breaks | id jumps | latency p50 "
           "ms | p95 ms | p50 first / last quarter ms | src skips | det drops | det p50 ms |\n"
        << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
           "---|\n";
    for (const std::string& video : split(args.get("videos"))) {
      if (!std::filesystem::exists(video)) {
        std::cout << "| " << video << " | absent, skipped |\n";
        continue;
      }
      std::vector<std::pair<std::string, std::string>> variants;  // detector, size
      for (const std::string& detector : split(args.get("detectors"))) {
        if (cli::detector_preset(detector).type != "detect.movenet") {
          variants.emplace_back(detector, "");
          continue;
        }
        for (const std::string& size : split(args.get("sizes")))
          variants.emplace_back(detector, size);
      }
      for (const auto& [detector, size] : variants) {
        const std::string label = size.empty() ? detector : detector + "@" + size;
        for (const auto& [backend, workers, threads, mode] : matrix(args)) {
          RunSpec spec;
          spec.backend = backend;
          spec.workers = std::stoi(workers);
          spec.video = video;
          spec.db = args.get("db");
          spec.detector = detector;
          if (!size.empty()) spec.size = std::stoi(size);
          spec.live = mode == "live";
          spec.detector_threads = std::stoi(threads);
          spec.lag = std::stoi(args.get(spec.live ? "live-lag" : "lag"));
          spec.print_stats = args.has("stats");
          spec.replay_fps = args.number("replay-fps");
          spec.out_dir = args.get("out") + "/" + std::filesystem::path(video).stem().string() +
                         "_" + label + "_" + backend + "_w" + workers + "_t" + threads + "_" +
                         mode + "_lag" + std::to_string(spec.lag);
          const Result r = run(spec);
          std::cout << std::fixed << std::setprecision(1) << "| "
                    << std::filesystem::path(video).filename().string() << " | " << label << " | "
                    << backend << " | " << workers << " | " << threads << " | " << mode << " | "
                    << r.frames << " | " << r.outputs << " | " << r.wall_s << " | " << r.fps
                    << " | " << std::setprecision(2) << r.people_mean << " (" << r.people_max
                    << ") | " << r.people3d_mean << " | " << r.quality.tracks << " | "
                    << r.quality.long_tracks << " | " << r.quality.breaks << " | "
                    << r.quality.jumps << " | " << std::setprecision(0);
          if (spec.live) {  // offline frames carry their time in the video, not a capture time
            std::cout << r.latency_p50_ms << " | " << r.latency_p95_ms << " | "
                      << r.latency_first_ms << " / " << r.latency_last_ms;
          } else {
            std::cout << "- | - | -";
          }
          std::cout << " | " << r.source_skips << " | " << r.detector_drops << " | "
                    << std::setprecision(1) << r.det_p50_ms << " |\n"
                    << std::flush;
        }
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "mocap-bench-video: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
