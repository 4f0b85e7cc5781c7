// mocap-bench-web: the frame rate the browser viewer sustains. A graph (synthetic walking people
// at a fixed rate -> sink.web) runs in this process while Debian's chromium (headless, through
// tests/web/viewer_test.mjs and playwright-core from the npm cache) shows the page; the page's own
// counters are read once a second for --seconds. Variants (people, input rate, antialiasing) run
// one after another in the same run. Prints a Markdown table; medians of the 1 s samples.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "graph/graph_spec.hpp"
#include "graph/runtime.hpp"
#include "graph/validation.hpp"
#include "support/network.hpp"
#include "web/web_server.hpp"

namespace {

using namespace mocap;
using Json = nlohmann::json;

struct Variant {
  int people = 6;
  double fps = 30;
  bool antialias = true;
};

struct Outcome {
  Json page;
  std::string sink_status;
  bool ok = false;
};

std::string read_text(const std::filesystem::path& path) {
  std::ostringstream text;
  if (std::FILE* f = std::fopen(path.c_str(), "r")) {
    char buffer[4096];
    for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, f)) > 0;)
      text.write(buffer, static_cast<std::streamsize>(n));
    std::fclose(f);
  }
  return text.str();
}

Outcome run_variant(const Variant& v, int seconds, const std::string& node,
                    const std::string& playwright) {
  const int port = test::free_tcp_port();
  std::ostringstream graph;
  graph << "graph: bench_web\nnodes:\n"
        << "  src: { type: unit.walking_people, params: { count: " << v.people << ", fps: " << v.fps
        << " } }\n"
        << "  web: { type: sink.web, params: { port: " << port
        << ", image_width: 640, image_height: 480, title: bench } }\n"
        << "edges:\n  - [src.out, web.in, { policy: latest }]\n";
  const graph::ResolvedGraph resolved =
      graph::resolve(graph::parse_graph_text(graph.str(), "bench"));
  graph::Runtime runtime(resolved);
  graph::RunResult run;
  std::thread runner([&] { run = runtime.run(); });
  const auto out = std::filesystem::temp_directory_path() /
                   ("mocap-bench-web-" + std::to_string(port) + ".json");
  const std::string url =
      "http://127.0.0.1:" + std::to_string(port) + "/" + (v.antialias ? "" : "?aa=0");
  const std::string command = "'" + node + "' '" MOCAP_VIEWER_SCRIPT "' --url '" + url +
                              "' --playwright '" + playwright + "' --frames 10 --people " +
                              std::to_string(v.people) + " --duration " + std::to_string(seconds) +
                              " > '" + out.string() + "' 2>&1";
  const int code = std::system(command.c_str());
  runtime.request_stop();
  runner.join();
  Outcome outcome;
  const std::string text = read_text(out);
  std::filesystem::remove(out);
  std::string line = text.substr(0, text.find_last_not_of('\n') + 1);
  line = line.substr(line.rfind('\n') == std::string::npos ? 0 : line.rfind('\n') + 1);
  outcome.page = Json::parse(line, nullptr, false);
  if (!outcome.page.is_object()) outcome.page = Json::object();
  outcome.ok = code == 0 && run.ok;
  if (!outcome.ok)
    std::cerr << "variant failed (exit " << code << "): " << text << run.error << "\n";
  for (const auto& n : run.stats.nodes) {
    if (n.node == "web") outcome.sink_status = n.status;
  }
  return outcome;
}

double number(const Json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : -1.0;
}

}  // namespace

int main(int argc, char** argv) {
  cli::Args args("mocap-bench-web [--seconds 10]",
                 "Frame rate of the browser viewer (headless chromium) with 6 people and other\n"
                 "variants; needs chromium, node and the npm cache of tools/setup.sh.");
  args.option("seconds", "S", "how long each variant is measured", "10")
      .option("variants", "LIST", "people:fps:aa,... (aa 1 or 0)", "6:30:1,6:30:0,6:60:0,1:30:1");
  int exit_code = 0;
  if (!args.parse(argc - 1, argv + 1, exit_code)) return exit_code;
  const std::string node = "/usr/bin/node";
  const std::string playwright =
      (web::default_three_dir().parent_path() / "playwright-core").string();
  if (!std::filesystem::exists("/usr/bin/chromium") || !std::filesystem::exists(node) ||
      !std::filesystem::exists(std::filesystem::path(playwright) / "index.mjs")) {
    std::cerr << "mocap-bench-web: needs /usr/bin/chromium, /usr/bin/node and " << playwright
              << " (tools/setup.sh)\n";
    return 1;
  }
  std::vector<Variant> variants;
  std::istringstream list(args.get("variants"));
  for (std::string item; std::getline(list, item, ',');) {
    Variant v;
    int aa = 1;
    if (std::sscanf(item.c_str(), "%d:%lf:%d", &v.people, &v.fps, &aa) != 3) {
      std::cerr << "mocap-bench-web: bad variant '" << item << "' (people:fps:aa)\n";
      return 2;
    }
    v.antialias = aa != 0;
    variants.push_back(v);
  }
  const int seconds = static_cast<int>(args.integer("seconds"));
  std::printf(
      "| people | input frames/s | antialias | page frames/s (median) | page renders/s (median) | "
      "frames received/s | 1 s samples | sink.web status |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const Variant& v : variants) {
    const Outcome o = run_variant(v, seconds, node, playwright);
    std::printf("| %d | %.0f | %s | %.1f | %.1f | %.1f | %s | %s |\n", v.people, v.fps,
                v.antialias ? "on" : "off", number(o.page, "fps_median"),
                number(o.page, "render_fps_median"), number(o.page, "received_per_second"),
                o.page.contains("fps_samples") ? o.page["fps_samples"].dump().c_str() : "-",
                o.sink_status.c_str());
    std::fflush(stdout);
  }
  return 0;
}
