// mocap-bench-rig-live: several fake GigE cameras (Aravis' arv-fake-gv-camera-0.8, each its own
// serial and loopback address, in a network namespace of this program's own) at one frame rate,
// through source.aravis into sink.sets, joined by capture time (the synchroniser every live
// multi-view graph uses), for --seconds. One camera is killed at a third of the run and started
// again at half: the others must go on (their sets partial while it is away) and it must come
// back. Prints one Markdown row per sample: sets, complete, missing per camera, skew p50/p95
// (over the last 1024 sets) and max, the sets' age when joined (capture to join, p50/p95), drops,
// resident memory; then the verdict. No detector by default (the fake frames have no people);
// --detector-ms D puts a stage of D ms per frame behind each camera (test.delay, a detector
// slower than the cameras), fed as the live graphs feed detectors (a `latest` edge per camera),
// or with --limit through flow.set_limiter (whole sets while every stage is idle, joined after
// by the limiter's set numbers). With --rtsp VIDEO the cameras are RTSP servers instead
// (tests/support/rtsp_server.py, GStreamer's gst-rtsp-server: VIDEO looped as live H.264, one
// server process per camera, each started once the one before listens, so their streams start
// at unrelated instants: free-running network cameras), read by source.video; the killed one is
// started again on its port. A benchmark, not a test: it takes minutes.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "cli_args.hpp"
#include "drivers/fake_gv_camera.hpp"
#include "drivers/private_loopback.hpp"
#include "graph/graph_spec.hpp"
#include "graph/runtime.hpp"
#include "graph/validation.hpp"
#include "support/rtsp_server.hpp"

namespace {

using namespace std::chrono_literals;
using namespace mocap;
using Clock = std::chrono::steady_clock;

double rss_mib() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return -1;
}

struct Settings {
  int cameras = 4;
  double fps = 30, tolerance_ms = 20, wait_ms = 200;
  int width = 320, height = 240;
  double detector_ms = 0;  // a slow stage per camera; 0: none
  bool limit = false;      // the slow stages fed through flow.set_limiter
  std::string rtsp_video;  // RTSP servers serving this video instead of fake GigE cameras
};

// The join after slow stages fed by the limiter: by its set numbers, waiting for a stage's output
// (or a camera the limiter had no frame of) up to a second.
constexpr double kJoinAfterLimiterWaitMs = 1000;

// `serials`: the fake cameras' serials, or with --rtsp the servers' URLs.
std::string graph_text(const Settings& s, const std::vector<std::string>& serials) {
  std::string text = "graph: rig_live_bench\nnodes:\n";
  char line[320];
  for (std::size_t i = 0; i < serials.size(); ++i) {
    if (s.rtsp_video.empty()) {
      std::snprintf(line, sizeof line,
                    "  cam%zu: { type: source.aravis, params: { id: %s, fps: %g, width: %d, "
                    "height: %d, pixel_format: Mono8, camera: cam%zu } }\n",
                    i + 1, serials[i].c_str(), s.fps, s.width, s.height, i + 1);
    } else {
      std::snprintf(line, sizeof line,
                    "  cam%zu: { type: source.video, params: { path: \"%s\", mode: live, "
                    "camera: cam%zu } }\n",
                    i + 1, serials[i].c_str(), i + 1);
    }
    text += line;
  }
  for (std::size_t i = 0; s.detector_ms > 0 && i < serials.size(); ++i) {
    std::snprintf(line, sizeof line, "  det%zu: { type: test.delay, params: { delay_ms: %g } }\n",
                  i + 1, s.detector_ms);
    text += line;
  }
  if (s.limit) {
    std::snprintf(line, sizeof line,
                  "  limit: { type: flow.set_limiter, params: { sync_tolerance_ms: %g, "
                  "sync_wait_ms: %g } }\n"
                  "  sets: { type: sink.sets, params: { sync_by: frame, sync_wait_ms: %g } }\n",
                  s.tolerance_ms, s.wait_ms, kJoinAfterLimiterWaitMs);
  } else {
    std::snprintf(line, sizeof line,
                  "  sets: { type: sink.sets, params: { sync_by: capture_time, "
                  "sync_tolerance_ms: %g, sync_wait_ms: %g } }\n",
                  s.tolerance_ms, s.wait_ms);
  }
  text += line;
  text += "edges:\n";
  for (std::size_t i = 0; i < serials.size(); ++i) {
    const std::string n = std::to_string(i + 1), k = std::to_string(i);
    std::string frames = "cam" + n + ".frames";
    if (s.limit) {
      text += "  - [" + frames + ", limit.frames:" + k + "]\n";
      frames = "limit.frames:" + k;
    }
    if (s.detector_ms > 0) {
      text +=
          "  - [" + frames + ", det" + n + ".in" + (s.limit ? "]\n" : ", { policy: latest }]\n");
      frames = "det" + n + ".out";
    }
    text += "  - [" + frames + ", sets.in:" + k + "]\n";
  }
  return text;
}

struct Sample {
  double t = 0;
  std::string event;
  graph::SyncStats sync;
  std::uint64_t drops = 0;
  double rss = 0;
  std::string last_status;
  std::string age;                // sink.sets' status: the sets' age when joined
  std::string limiter;            // flow.set_limiter's status
  graph::SyncStats limiter_sync;  // its join by capture time
};

// `watched`: the node whose status line is kept (the camera killed and restarted).
Sample sample(const graph::Runtime& runtime, double t, std::string event,
              const std::string& watched) {
  Sample s;
  s.t = t;
  s.event = std::move(event);
  s.rss = rss_mib();
  for (const graph::NodeStats& n : runtime.stats().nodes) {
    s.drops += n.drops;
    if (n.node == "sets") {
      s.sync = n.sync;
      s.age = n.status;
    }
    if (n.node == "limit") {
      s.limiter = n.status;
      s.limiter_sync = n.sync;
    }
    if (n.node == watched) s.last_status = n.status;
  }
  return s;
}

void print_header(int cameras) {
  std::cout << "| t s | event | sets | complete |";
  for (int i = 1; i <= cameras; ++i) std::cout << " cam" << i << " missing |";
  std::cout << " skew p50 ms | skew p95 ms | skew max ms | age when joined | drops | RSS MiB "
               "|\n|---|---|---|---|";
  for (int i = 0; i < cameras; ++i) std::cout << "---|";
  std::cout << "---|---|---|---|---|---|\n";
}

void print_row(const Sample& s) {
  std::printf("| %.0f | %s | %llu | %llu |", s.t, s.event.c_str(),
              static_cast<unsigned long long>(s.sync.sets),
              static_cast<unsigned long long>(s.sync.complete));
  for (const auto& input : s.sync.inputs)
    std::printf(" %llu |", static_cast<unsigned long long>(input.missing));
  const std::string age = s.age.rfind("age when joined ", 0) == 0 ? s.age.substr(16) : s.age;
  std::printf(" %.2f | %.2f | %.2f | %s | %llu | %.1f |\n", s.sync.skew_p50_ms, s.sync.skew_p95_ms,
              s.sync.skew_max_ms, age.c_str(), static_cast<unsigned long long>(s.drops), s.rss);
  std::fflush(stdout);
}

// The cameras under test: fake GigE cameras (each its serial and loopback address) or RTSP
// servers (each its process and port); the last one can be killed and started again as it was.
class BenchCameras {
 public:
  explicit BenchCameras(const Settings& s) : settings_(s) {
    if (s.rtsp_video.empty()) {
      program_ = test::fake_camera_program();
      if (!program_) {
        problem_ = std::string(test::kFakeCameraProgram) + " not on PATH (package aravis-tools)";
        return;
      }
    }
    for (int i = 0; i < s.cameras && problem_.empty(); ++i) start(i, 0);
  }
  const std::string& problem() const { return problem_; }
  // What the graph's sources open: the serials, or the servers' URLs.
  const std::vector<std::string>& ids() const { return ids_; }
  void kill_last() {
    if (!fake_.empty()) fake_.back()->stop();
    if (!rtsp_.empty()) rtsp_.back()->stop();
  }
  // On the same port (RTSP): the source reconnects to the URL it had.
  void restart_last() {
    const int last = settings_.cameras - 1;
    const std::string& id = ids_.back();
    start(last, settings_.rtsp_video.empty() ? 0 : std::stoi(id.substr(id.rfind(':') + 1)));
  }

 private:
  void start(int i, int port) {
    const bool again = static_cast<std::size_t>(i) < ids_.size();
    if (settings_.rtsp_video.empty()) {
      const std::string serial = "BENCH" + std::to_string(i + 1);
      auto camera = std::make_unique<test::FakeGvCamera>(*program_, serial, 0, 15s,
                                                         "127.0.0." + std::to_string(i + 1));
      if (again) {
        fake_.back() = std::move(camera);
      } else {
        fake_.push_back(std::move(camera));
        ids_.push_back(serial);
      }
      return;
    }
    test::RtspServerOptions o;
    o.video = settings_.rtsp_video;
    o.width = settings_.width;
    o.height = settings_.height;
    o.frames = 150;  // decoded once and held: 5 s looped
    o.fps = settings_.fps;
    o.loop = true;
    o.port = port;
    auto server = std::make_unique<test::RtspServer>(dir_, "cam" + std::to_string(i + 1), o);
    if (!server->problem().empty()) {
      problem_ = server->problem();
      return;
    }
    if (again) {
      rtsp_.back() = std::move(server);
    } else {
      ids_.push_back(server->url());
      rtsp_.push_back(std::move(server));
    }
  }

  const Settings& settings_;
  std::optional<std::string> program_;
  test::TempDir dir_;  // the servers' output
  std::vector<std::unique_ptr<test::FakeGvCamera>> fake_;
  std::vector<std::unique_ptr<test::RtspServer>> rtsp_;
  std::vector<std::string> ids_;
  std::string problem_;
};

}  // namespace

int main(int argc, char** argv) {
  // Before any thread starts (user namespaces require a single-threaded process).
  const std::string loopback = test::enter_private_loopback(8);
  cli::Args args("mocap-bench-rig-live [options]",
                 "Fake GigE cameras (or RTSP servers) joined by capture time for minutes; one "
                 "killed and restarted.");
  args.option("seconds", "S", "run length", "300", cli::Range::at_least(12))
      .option("cameras", "N", "cameras (2..8)", "4", cli::Range::count(2, 8))
      .option("fps", "F", "frame rate of every camera", "30", cli::Range::between(1, 120))
      .option("tolerance-ms", "MS", "sync_tolerance_ms", "20", cli::Range::positive())
      .option("wait-ms", "MS", "sync_wait_ms", "200", cli::Range::positive())
      .option("size", "WxH", "frame size", "320x240", cli::Range::image_size())
      .option("detector-ms", "MS",
              "a stage of MS per frame behind each camera (test.delay; 0: none)", "0",
              cli::Range::between(0, 10000))
      .flag("limit",
            "feed the stages through flow.set_limiter (whole sets) instead of a "
            "latest edge each")
      .option("rtsp", "VIDEO",
              "RTSP servers serving VIDEO (looped, live H.264, one process per camera; "
              "tests/support/rtsp_server.py, run from the source folder) instead of fake GigE "
              "cameras");
  int code = 0;
  if (!args.parse(argc - 1, argv + 1, code)) return code;
  if (!loopback.empty()) {
    std::cerr << "mocap-bench-rig-live: " << loopback << "\n";
    return 1;
  }
  Settings s;
  s.cameras = static_cast<int>(args.integer("cameras"));
  s.fps = args.number("fps");
  s.tolerance_ms = args.number("tolerance-ms");
  s.wait_ms = args.number("wait-ms");
  s.width = args.image_size("size").width;
  s.height = args.image_size("size").height;
  s.detector_ms = args.number("detector-ms");
  s.limit = args.has("limit");
  if (args.has("rtsp")) s.rtsp_video = args.get("rtsp");
  const double seconds = args.number("seconds");

  BenchCameras cameras(s);
  if (!cameras.problem().empty()) {
    std::cerr << "mocap-bench-rig-live: " << cameras.problem() << "\n";
    return 1;
  }
  graph::Runtime runtime(
      graph::resolve(graph::parse_graph_text(graph_text(s, cameras.ids()), "rig_live_bench")));
  graph::RunResult result;
  const auto start = Clock::now();
  std::thread run([&] { result = runtime.run(); });
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };

  char stage[96] = "no detector";
  if (s.detector_ms > 0)
    std::snprintf(stage, sizeof stage, "a %g ms stage per camera %s", s.detector_ms,
                  s.limit ? "behind flow.set_limiter" : "on a latest edge");
  const std::string kind =
      s.rtsp_video.empty() ? "fake GigE cameras" : "RTSP servers (" + s.rtsp_video + ", H.264)";
  std::printf(
      "%d %s at %g fps (%dx%d), sync_tolerance_ms %g, sync_wait_ms %g, %g s; cam%d killed at "
      "%.0f s, restarted at %.0f s; %s\n\n",
      s.cameras, kind.c_str(), s.fps, s.width, s.height, s.tolerance_ms, s.wait_ms, seconds,
      s.cameras, seconds / 3, seconds / 2, stage);
  print_header(s.cameras);
  std::vector<Sample> samples;
  const std::string watched = "cam" + std::to_string(s.cameras);
  const double kill_at = seconds / 3, restart_at = seconds / 2, step = seconds / 10;
  bool killed = false, restarted = false;
  double next_sample = 5;  // after warm-up
  while (elapsed() < seconds) {
    std::this_thread::sleep_for(100ms);
    const double t = elapsed();
    std::string event;
    if (!killed && t >= kill_at) {
      samples.push_back(sample(runtime, t, "before kill", watched));
      print_row(samples.back());
      cameras.kill_last();
      killed = true;
      event = "cam" + std::to_string(s.cameras) + " killed";
    } else if (!restarted && t >= restart_at) {
      samples.push_back(sample(runtime, t, "before restart", watched));
      print_row(samples.back());
      cameras.restart_last();
      restarted = true;
      event = "cam" + std::to_string(s.cameras) + " restarted";
    } else if (t < next_sample) {
      continue;
    }
    samples.push_back(sample(runtime, elapsed(), event, watched));
    print_row(samples.back());
    while (next_sample <= t) next_sample += step;
  }
  samples.push_back(sample(runtime, elapsed(), "end", watched));
  print_row(samples.back());
  runtime.request_stop();
  run.join();

  // The verdict.
  const Sample& warm = samples.front();
  const Sample& end = samples.back();
  const auto find = [&](const std::string& event) {
    return *std::find_if(samples.begin(), samples.end(),
                         [&](const Sample& x) { return x.event == event; });
  };
  const Sample before_kill = find("before kill"), before_restart = find("before restart");
  const std::size_t lost = static_cast<std::size_t>(s.cameras - 1);
  const auto missing = [&](const Sample& x) { return x.sync.inputs.at(lost).missing; };
  const auto received = [&](const Sample& x, std::size_t i) {
    return x.sync.inputs.at(i).received;
  };
  const double away_s = before_restart.t - before_kill.t;
  std::printf("\nwhile cam%d was away (%.0f s): %llu sets without it (%.1f per s); ", s.cameras,
              away_s,
              static_cast<unsigned long long>(missing(before_restart) - missing(before_kill)),
              static_cast<double>(missing(before_restart) - missing(before_kill)) / away_s);
  std::printf(
      "the others received %llu frames (%.1f per s each)\n",
      static_cast<unsigned long long>(received(before_restart, 0) - received(before_kill, 0)),
      static_cast<double>(received(before_restart, 0) - received(before_kill, 0)) / away_s);
  std::printf("cam%d after its restart: %llu frames received; its status: %s\n", s.cameras,
              static_cast<unsigned long long>(received(end, lost) - received(before_restart, lost)),
              end.last_status.c_str());
  // The cameras start one after the other: the first sets are partial until all stream.
  const auto share = [](const Sample& a, const Sample& b, const char* what) {
    const auto sets = b.sync.sets - a.sync.sets, complete = b.sync.complete - a.sync.complete;
    std::printf("%s (%.0f..%.0f s): %llu sets, %llu complete (%.1f %%)\n", what, a.t, b.t,
                static_cast<unsigned long long>(sets), static_cast<unsigned long long>(complete),
                100.0 * static_cast<double>(complete) /
                    static_cast<double>(std::max<std::uint64_t>(sets, 1)));
  };
  share(warm, before_kill, "all cameras, after warm-up");
  const auto back = std::find_if(samples.begin(), samples.end(), [&](const Sample& x) {
    return x.t >= before_restart.t + 10;  // reconnected by then
  });
  if (back != samples.end()) share(*back, end, "all cameras again, after the restart");
  std::printf("memory: %.1f MiB after warm-up, %.1f MiB at the middle, %.1f MiB at the end\n",
              warm.rss, samples[samples.size() / 2].rss, end.rss);
  std::printf("sets: %llu, complete %llu (%.1f %%), late %llu, restarts %llu; run %s\n",
              static_cast<unsigned long long>(end.sync.sets),
              static_cast<unsigned long long>(end.sync.complete),
              100.0 * static_cast<double>(end.sync.complete) /
                  static_cast<double>(std::max<std::uint64_t>(end.sync.sets, 1)),
              static_cast<unsigned long long>([&] {
                std::uint64_t late = 0;
                for (const auto& i : end.sync.inputs) late += i.late;
                return late;
              }()),
              static_cast<unsigned long long>(end.sync.restarts),
              result.ok ? "ok" : result.error.c_str());
  std::cout << graph::format_sync_stats(end.sync) << "\n";
  std::printf("sets' %s\n", end.age.c_str());
  if (s.limit) {
    std::printf("limiter: %s\n", end.limiter.c_str());
    std::cout << "limiter's join: " << graph::format_sync_stats(end.limiter_sync) << "\n";
  }
  return result.ok ? 0 : 1;
}
