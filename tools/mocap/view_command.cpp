// `mocap view`: the browser viewer (docs/viewer.md) on a recording (poses.jsonl, played with a
// timeline the page controls) or on a running graph (a sink.web is attached to the People3D
// output of its last stage when the graph has none).

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <optional>

#include "camera/camera_file.hpp"
#include "camera/rig_file.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "graph/plugins.hpp"
#include "graph/signals.hpp"
#include "graph/validation.hpp"
#include "graph_runner.hpp"
#include "web/frame_json.hpp"
#include "web/recording.hpp"
#include "web/web_server.hpp"

namespace mocap::cli {
namespace {

using namespace std::chrono_literals;

std::optional<web::ShownCamera> camera_of(const Args& args) {
  if (args.has("camera")) return web::ShownCamera{camera::read_camera_file(args.get("camera"))};
  if (!args.has("image-size")) return std::nullopt;
  const ImageSize size = args.image_size("image-size");
  return web::ShownCamera{camera::Camera::from_fov(size.width, size.height, args.number("hfov")),
                          true};
}

// The recording's 2D keypoints must lie in the image the camera says: a smaller image would draw
// them, and the frustum, wrong.
void check_keypoints_inside(const web::Recording& recording,
                            const std::optional<web::ShownCamera>& shown, const std::string& path,
                            const Args& args) {
  if (!shown) return;
  const camera::Camera& camera = shown->camera;
  for (std::size_t f = 0; f < recording.frames.size(); ++f) {
    for (const Person3D& person : recording.frames[f].people) {
      for (const Keypoint2D& k : person.keypoints) {
        if (!(k.confidence > 0.0f)) continue;
        if (k.x <= static_cast<float>(camera.width) + 1.0f &&
            k.y <= static_cast<float>(camera.height) + 1.0f)
          continue;
        throw InputError(args.has("camera") ? args.get("camera") : "--image-size",
                         std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                             " is smaller than the keypoints of " + path + " (frame " +
                             std::to_string(f) + " has one at " + std::to_string(k.x) + ", " +
                             std::to_string(k.y) + "): give the size of the input images");
      }
    }
  }
}

// A recording in a rig's world (joints_world) is drawn with the rig's cameras (--rig; without
// it, with none); a camera's recording with that camera (--camera, --image-size).
std::optional<camera::Rig> rig_of(const web::Recording& recording, const std::string& path,
                                  const Args& args) {
  if (!recording.world) {
    if (args.has("rig"))
      throw InputError(path,
                       "people in a camera's frame (joints_abs or none), not in a rig's "
                       "world: give its camera with --camera or --image-size, not --rig");
    return std::nullopt;
  }
  if (args.has("camera") || args.has("image-size"))
    throw InputError(path,
                     "people in a rig's world (joints_world): give the rig with --rig, "
                     "not --camera or --image-size");
  if (!args.has("rig")) {
    std::cerr << "mocap view: " << path
              << ": people in a rig's world; --rig RIG would draw its cameras\n";
    return camera::Rig{};
  }
  return camera::read_rig(args.get("rig"));
}

int view_recording(const Args& args) {
  const std::string path = args.positionals()[0];
  const web::Recording recording = web::read_poses_jsonl(path, args.number("fps"));
  if (recording.cut_last_line)
    std::cerr << "mocap view: " << path
              << ": the last line is cut (the writer was killed while writing it): skipped\n";
  const std::optional<web::ShownCamera> camera = camera_of(args);
  check_keypoints_inside(recording, camera, path, args);
  const std::optional<camera::Rig> rig = rig_of(recording, path, args);

  std::mutex mutex;
  std::condition_variable changed;
  bool stop = false, control = false;
  web::Player player(recording.times);
  graph::SignalWatcher watcher([&](int, int) {
    const std::lock_guard lock(mutex);
    stop = true;
    changed.notify_all();
  });

  web::ServerOptions options;
  options.host = args.get("host");
  options.port = static_cast<int>(args.integer("port"));
  options.queue_frames = static_cast<std::size_t>(args.integer("queue"));
  options.three_dir = web::default_three_dir();
  options.greeting = web::hello_json(std::filesystem::path(path).filename().string());
  options.on_message = [&](const std::string& message) {
    const std::lock_guard lock(mutex);
    if (player.apply(message)) {
      control = true;
      changed.notify_all();
    }
  };
  if (!std::filesystem::exists(options.three_dir / "build" / "three.module.js"))
    std::cerr << "mocap view: warning: three.js not found in " << options.three_dir
              << " (run tools/setup.sh); the page cannot draw\n";
  web::WebServer server(std::move(options));
  std::cout << "mocap view: " << recording.frames.size() << " frames (" << recording.times.back()
            << " s) of " << path << " at " << server.url() << " (Ctrl-C to stop)" << std::endl;

  // The server thread only changes the player; this loop moves its clock and sends a frame
  // whenever the one to show changes (or a control arrives, so the page sees the new state).
  std::unique_lock lock(mutex);
  auto last = std::chrono::steady_clock::now();
  std::optional<std::size_t> shown;
  while (!stop) {
    const auto now = std::chrono::steady_clock::now();
    const std::size_t index = player.advance(std::chrono::duration<double>(now - last).count());
    last = now;
    if (index != shown || control) {
      shown = index;
      control = false;
      const web::Playback playback{index, player.count(), player.playing(), player.speed(),
                                   player.duration()};
      const People3D& frame = recording.frames[index];
      server.broadcast(rig ? web::frame_json(frame, *rig, playback, recording.times[index])
                           : web::frame_json(frame, camera, playback, recording.times[index]));
    }
    changed.wait_for(lock, 4ms, [&] { return stop || control; });
  }
  std::cerr << "mocap view: stopped\n";
  return 0;
}

bool is_loopback_host(const std::string& host) {
  return host == "localhost" || host == "::1" || host == "[::1]" || host.rfind("127.", 0) == 0;
}

// The People3D output of the graph's last stage that makes one (in topological order).
std::optional<graph::PortRef> last_people3d_output(const graph::ResolvedGraph& graph) {
  std::optional<graph::PortRef> found;
  for (const graph::ResolvedNode& node : graph.nodes) {
    const auto& outputs = node.type->contract.outputs();
    for (std::size_t i = 0; i < outputs.size() && i < node.output_types.size(); ++i) {
      if (node.output_types[i] == "People3D") found = graph::PortRef{node.name, outputs[i].name};
    }
  }
  return found;
}

int view_graph(const Args& args) {
  graph::load_plugins_from_environment();
  graph::GraphSpec spec = graph::load_graph_file(args.get("graph"));
  apply_overrides(spec, args.all("set"));
  if (args.has("allow-network")) spec.allow_network = true;
  const graph::ResolvedGraph plain = graph::resolve(spec);
  const graph::SourceLocation here{"mocap view", 0};
  bool has_viewer = false;
  for (graph::NodeSpec& node : spec.nodes) {
    if (node.type != "sink.web") continue;
    has_viewer = true;
    if (args.has("host")) node.params["host"] = {args.get("host"), here};
    if (args.has("port")) node.params["port"] = {args.get("port"), here};
  }
  if (!has_viewer) {
    const auto from = last_people3d_output(plain);
    if (!from) throw InputError(args.get("graph"), "no node of the graph sends People3D");
    std::string name = "view";
    while (spec.find_node(name)) name += "_";
    graph::NodeSpec node;
    node.name = name;
    node.type = "sink.web";
    node.where = here;
    node.params["host"] = {args.get("host"), here};
    node.params["port"] = {args.has("port") ? args.get("port") : "8080", here};
    node.params["title"] = {spec.name, here};
    spec.nodes.push_back(node);
    // `latest`: the viewer shows the newest frame and never holds the graph back.
    graph::EdgeSpec edge;
    edge.from = *from;
    edge.to = {name, "in"};
    edge.policy = {graph::PolicyKind::latest, 1};
    edge.where = here;
    spec.edges.push_back(edge);
    std::cerr << "mocap view: sink.web '" << name << "' attached to " << from->str() << "\n";
  }
  const graph::ResolvedGraph graph = graph::resolve(std::move(spec));
  graph::RunOptions options;
  options.single_process = true;  // one process: the viewer sees the graph's last stage directly
  const graph::RunResult result = run_graph_here(graph, options, "mocap view");
  if (!args.has("quiet")) std::cerr << graph::format_stats_table(result.stats);
  if (!result.ok) {
    std::cerr << "mocap view: " << result.error << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int view_command(int argc, char** argv) {
  Args args(
      "mocap view POSES.jsonl [--port P] | mocap view --graph GRAPH [--set node.param=value]",
      "Shows people in 3D in the browser. With POSES.jsonl (sink.jsonl, mocap reconstruct):\n"
      "plays the recording with play, pause, timeline and speed. With --graph: runs the graph\n"
      "in this process with a sink.web on the People3D output of its last stage (unless it\n"
      "has one). Open the printed URL; loopback only unless --host says otherwise.");
  args.positional("POSES", "poses.jsonl to play (not with --graph)", false, false)
      .option("graph", "GRAPH", "run this graph file with a viewer attached")
      .option("set", "NODE.PARAM=VALUE", "override a node parameter (with --graph)", std::nullopt,
              true)
      .option("host", "ADDRESS",
              "address to serve on (0.0.0.0: every interface, with --allow-network)", "127.0.0.1")
      .flag("allow-network",
            "let --host be an address other machines reach (the page has no authentication)")
      .option("port", "P", "TCP port; 0 picks a free one (graph: 8080 unless given)", "8080",
              Range::count(0, 65535))
      .option("queue", "N", "frames waiting per browser before the oldest is dropped", "4",
              Range::count(1, 1000))
      .option("fps", "F", "frame rate of a recording without usable times", "30",
              Range::between(0.1, 1000.0))
      .option("camera", "FILE", "camera file (a rig file of one camera): draw its frustum")
      .option("image-size", "WxH", "or the image size, with --hfov, for an assumed camera",
              std::nullopt, Range::image_size())
      .option("hfov", "DEG", "horizontal field of view with --image-size", "60",
              Range::between(1.0, 179.0))
      .option("rig", "RIG",
              "rig file (.toml, .yml) of a recording in its world (joints_world, mocap "
              "reconstruct --calibration): draw every camera where it stands")
      .flag("quiet", "do not print the graph's statistics at the end");
  int exit_code = 0;
  if (!args.parse(argc, argv, exit_code)) return exit_code;
  const bool graph = args.has("graph");
  if (graph == !args.positionals().empty()) {
    std::cerr << "mocap view: give either POSES.jsonl or --graph GRAPH\n\n" << args.help();
    return 2;
  }
  if (!graph && !is_loopback_host(args.get("host")) && !args.has("allow-network")) {
    std::cerr << "mocap view: --host " << args.get("host")
              << " serves the page beyond this machine, to anyone, without authentication; add "
                 "--allow-network to allow it\n";
    return 2;
  }
  return graph ? view_graph(args) : view_recording(args);
}

}  // namespace mocap::cli
