// `mocap reconstruct INPUT --db DB --out DIR`: runs the monocular graph
// (graphs/monocular_json.yaml) on a folder of OpenPose JSON and writes poses.jsonl, one BVH per
// person and summary.json.

#include <unistd.h>

#include <chrono>
#include <climits>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "eval_report.hpp"
#include "graph/graph_spec.hpp"
#include "graph/plugins.hpp"
#include "graph/validation.hpp"
#include "graph_runner.hpp"

namespace mocap::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The repository (or install) folder: the executable lives in <root>/build/bin.
fs::path install_root() {
  char path[PATH_MAX];
  const ssize_t size = readlink("/proc/self/exe", path, sizeof path - 1);
  if (size <= 0) return fs::current_path();
  return fs::path(std::string(path, static_cast<std::size_t>(size)))
      .parent_path()
      .parent_path()
      .parent_path();
}

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

void configure(graph::GraphSpec& spec, const Args& args, const fs::path& out) {
  set_param(spec, "source.openpose_json", "path", args.positionals()[0]);
  for (const char* type : {"source.openpose_json", "sink.bvh", "sink.overlay"})
    set_param(spec, type, "fps", args.get("fps"));
  for (const char* type :
       {"recon.scaler", "recon.matcher", "recon.temporal_selector", "sink.bvh"}) {
    set_param(spec, type, "db", args.get("db"));
  }
  set_param(spec, "recon.temporal_selector", "mode", args.get("mode"));
  if (args.has("image-size")) {
    const std::string size = args.get("image-size");
    const auto x = size.find('x');
    if (x == std::string::npos || x == 0 || x + 1 == size.size() ||
        size.find_first_not_of("0123456789x") != std::string::npos) {
      throw InputError("--image-size",
                       "expected WIDTHxHEIGHT in pixels, e.g. 1920x1080, got '" + size + "'");
    }
    set_param(spec, "recon.temporal_selector", "image_width", size.substr(0, x));
    set_param(spec, "recon.temporal_selector", "image_height", size.substr(x + 1));
    set_param(spec, "recon.temporal_selector", "hfov_deg", args.get("hfov"));
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
  std::size_t frames = 0, person_frames = 0;
  for (std::string line; std::getline(in, line);) {
    const json j = json::parse(line, nullptr, false);
    if (j.is_discarded()) continue;
    ++frames;
    for (const auto& p : j.value("people", json::array())) {
      ++frames_per_id[p.value("id", -1)];
      ++person_frames;
    }
  }
  int long_tracks = 0;
  for (const auto& [id, n] : frames_per_id) long_tracks += n > 50 ? 1 : 0;
  return {{"frames", frames},
          {"people", frames_per_id.size()},
          {"person_frames", person_frames},
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
      "Reconstructs the 3D motion of every person in a folder of OpenPose *_keypoints.json files\n"
      "(BODY_25, BODY_25B, COCO-18). Writes into DIR: poses.jsonl (one line per input frame: 15 "
      "joints\n"
      "per person, metres, camera coordinates, root-relative), person_<id>.bvh per person (when "
      "the\n"
      "graph has a sink.bvh) and summary.json.");
  args.positional("INPUT", "folder of OpenPose *_keypoints.json files")
      .option("out", "DIR", "output folder (created)")
      .option("db", "FILE", "pose database", default_database())
      .option("fps", "N", "frame rate of the keypoints' video", "30")
      .option("image-size", "WxH",
              "size of the images the keypoints came from; turns each pose onto its camera ray "
              "(off when absent)")
      .option("hfov", "DEG", "horizontal field of view assumed with --image-size", "60")
      .option("mode", "NAME",
              "temporal selection: path (Viterbi, lag 8), greedy (the paper) or nearest", "path")
      .option("graph", "FILE", "graph to run",
              (install_root() / "graphs" / "monocular_json.yaml").string())
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
  if (!fs::is_directory(args.positionals()[0]))
    throw InputError(args.positionals()[0], "not a folder of OpenPose JSON files");
  const fs::path out = args.get("out");
  fs::create_directories(out);

  graph::load_plugins_from_environment();
  graph::GraphSpec spec = graph::load_graph_file(args.get("graph"));
  configure(spec, args, out);
  graph::apply_overrides(spec, args.all("set"));
  const graph::ResolvedGraph resolved = graph::resolve(std::move(spec));

  const auto started = std::chrono::steady_clock::now();
  graph::RunOptions options;
  options.single_process = true;
  const graph::RunResult result = run_graph_here(resolved, options, "mocap reconstruct");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!args.has("quiet")) std::cerr << graph::format_stats_table(result.stats);

  json summary = summarize_output(out / "poses.jsonl");
  summary["input"] = args.positionals()[0];
  summary["database"] = args.get("db");
  summary["mode"] = args.get("mode");
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
  for (const auto& e : fs::directory_iterator(out)) {
    if (e.path().extension() == ".bvh" || e.path().extension() == ".mp4")
      std::cout << "wrote " << e.path().string() << "\n";
  }
  std::cout << "wrote " << (out / "summary.json").string() << "\n";
  if (!result.ok) {
    std::cerr << "mocap reconstruct: " << result.error << "\n";
    return 1;
  }
  return result.stopped ? 130 : 0;
}

}  // namespace mocap::cli
