// sink.web: the live 3D viewer in the browser (docs/viewer.md). Serves the page on
// http://HOST:PORT/ (loopback by default; port 0 picks a free one) and sends every People3D frame
// to each connected browser over a WebSocket. A slow browser loses frames (a bounded queue per
// browser, drops shown in the node's status); the graph never waits for a browser.

#include <chrono>
#include <iostream>
#include <memory>
#include <optional>

#include "camera/rig_file.hpp"
#include "graph/registry.hpp"
#include "nodes/recon/node_camera.hpp"
#include "web/frame_json.hpp"
#include "web/web_server.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class WebSink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Live 3D viewer in the browser: serves a page and streams every frame over a WebSocket");
    c.input<People3D>("in");
    c.param<std::string>("host", "127.0.0.1",
                         "address to serve on (loopback; 0.0.0.0 for every interface, which "
                         "needs allow_network: true)");
    c.serves_http("host");
    c.param<int>("port", 8080, "TCP port (0: a free one; the URL is printed)", {0, 65535});
    c.param<int>("queue", 4, "frames waiting per browser before the oldest is dropped", {1, 1000});
    c.param<std::string>("title", "mocap", "title shown by the page");
    c.param<std::string>("three_dir", "",
                         "the npm package three (default: the npm cache of tools/setup.sh)");
    declare_camera_params(c);
    c.param<std::string>("rig", "",
                         "rig file (.toml, .yml) of world-frame people (multi-view): its cameras "
                         "are drawn where they stand");
  }

  void open(Context& ctx) override {
    if (NodeCamera camera = read_camera_params(ctx); camera.known())
      camera_ = web::ShownCamera{std::move(camera.camera), camera.assumed};
    if (const std::string rig = ctx.param<std::string>("rig"); !rig.empty())
      rig_ = camera::read_rig(rig);  // throws naming the file
    web::ServerOptions options;
    options.host = ctx.param<std::string>("host");
    options.port = ctx.param<int>("port");
    options.queue_frames = static_cast<std::size_t>(ctx.param<int>("queue"));
    const std::string three = ctx.param<std::string>("three_dir");
    options.three_dir = three.empty() ? web::default_three_dir() : std::filesystem::path(three);
    options.greeting = web::hello_json(ctx.param<std::string>("title"));
    if (!std::filesystem::exists(options.three_dir / "build" / "three.module.js"))
      std::cerr << "sink.web: warning: three.js not found in " << options.three_dir
                << " (run tools/setup.sh); the page cannot draw\n";
    server_ = std::make_unique<web::WebServer>(std::move(options));
    std::cerr << "sink.web: viewer at " << server_->url() << "\n";
    ctx.report_status(server_->url());
  }

  void process(Context& ctx) override {
    const auto& people = ctx.input<People3D>("in");
    server_->broadcast(people.frame.is_world() ? web::frame_json(people, rig_)
                                               : web::frame_json(people, camera_));
    const auto now = std::chrono::steady_clock::now();
    if (now - last_status_ > std::chrono::seconds(1)) {
      last_status_ = now;
      const web::ServerStats s = server_->stats();
      ctx.report_status(server_->url() + ", " + std::to_string(s.clients) + " browser(s), " +
                        std::to_string(s.dropped) + " frame(s) dropped for slow browsers");
    }
  }

  void close(Context&) override { server_.reset(); }

 private:
  std::optional<web::ShownCamera> camera_;
  camera::Rig rig_;  // for world-frame people; none: no camera drawn
  std::unique_ptr<web::WebServer> server_;
  std::chrono::steady_clock::time_point last_status_{};
};

MOCAP_REGISTER_NODE("sink.web", WebSink)

}  // namespace mocap::nodes
