// mocap-soak: a two-process graph over tcp://127.0.0.1 run by `mocap run` (supervised) for N
// minutes: a real video replayed in a loop at its own rate (source.video, live, loop) in process
// `capture`, a deliberately slow consumer (test.delay, longer than the frame period) and a
// measuring sink (test.probe) in process `solve`. It samples the resident memory (VmRSS) of the
// supervisor and both groups every few seconds, reads the probe's lines as they come (sequence
// number, latency from capture to sink) and prints one Markdown row per minute: messages,
// drops, RSS per process, latency p50/p95. At the end it stops the graph with SIGTERM (exit time
// and code) and prints RSS after warm-up against the end, the runtime's own statistics and a
// verdict.
//
//   --edge latest:   the slow consumer takes the newest frame; drops are counted and must match
//                    the sequence numbers that never reached the probe; memory must stay flat.
//   --edge blocking: the producer waits (the live source skips frames it is late for, before
//                    they get a sequence number); every sequence number must arrive exactly once,
//                    in order, and their count must equal the frames the source sent.

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <regex>
#include <sstream>
#include <thread>

#include "cli_args.hpp"
#include "support/mocap_process.hpp"
#include "support/network.hpp"

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// VmRSS of a process in MiB; -1 when it is gone.
double rss_mib(int pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return -1;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  const auto rank = static_cast<std::size_t>(std::clamp(
      p / 100.0 * static_cast<double>(v.size()) - 0.5, 0.0, static_cast<double>(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(rank), v.end());
  return v[rank];
}

// The probe's file, read as it grows: complete lines only.
class ProbeReader {
 public:
  explicit ProbeReader(std::string path) : path_(std::move(path)) {}
  struct Line {
    std::uint64_t seq;
    double latency_us;
  };
  std::vector<Line> next() {
    std::vector<Line> lines;
    std::ifstream in(path_, std::ios::binary);
    if (!in) return lines;
    in.seekg(static_cast<std::streamoff>(offset_));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t end = text.rfind('\n');
    if (end == std::string::npos) return lines;
    std::istringstream complete(text.substr(0, end + 1));
    for (std::string line; std::getline(complete, line);) {
      Line l{};
      if (std::sscanf(line.c_str(), "%lu %lf", &l.seq, &l.latency_us) == 2) lines.push_back(l);
    }
    offset_ += end + 1;
    return lines;
  }

 private:
  std::string path_;
  std::size_t offset_ = 0;
};

struct Minute {
  std::uint64_t messages = 0, drops = 0;
  std::map<std::string, double> rss;  // the last sample of the minute
  double p50_ms = 0, p95_ms = 0;
};

std::string graph_text(const std::string& video, const std::string& edge, double delay_ms, int port,
                       const std::string& probe) {
  const std::string policy = edge == "latest" ? "latest" : "blocking(4)";
  std::ostringstream g;
  g << "graph: soak_" << edge << "\n"
    << "nodes:\n"
    << "  src:   { type: source.video, params: { path: \"" << video
    << "\", mode: live, loop: true, stream: soak } }\n"
    << "  slow:  { type: test.delay, params: { delay_ms: " << delay_ms << " } }\n"
    << "  probe: { type: test.probe, params: { path: \"" << probe << "\" } }\n"
    << "edges:\n"
    << "  - [src.frames, slow.in, { transport: \"tcp://127.0.0.1:" << port
    << "\", policy: " << policy << " }]\n"
    << "  - [slow.out, probe.in]\n"
    << "processes:\n  capture: [src]\n  solve: [slow, probe]\n";
  return g.str();
}

}  // namespace

int main(int argc, char** argv) {
  mocap::cli::Args args("mocap-soak [--minutes N] [--edge latest|blocking]",
                        "Soak test: a two-process graph over tcp://127.0.0.1 with a slow "
                        "consumer, memory, latency and drops per minute.");
  args.option("minutes", "N", "how long to run", "10")
      .option("edge", "POLICY", "latest or blocking", "latest")
      .option("video", "PATH", "video replayed in a loop",
              "../shared/data/eval/opencv_samples/vtest_part0.avi")
      .option("delay-ms", "MS", "time the slow consumer spends per frame", "150")
      .option("sample-s", "S", "seconds between memory samples", "5")
      .option("mocap", "PATH", "the mocap program", MOCAP_BINARY)
      .option("keep", "DIR", "write the graph, logs and probe file here (default: a temp dir)");
  int exit_code = 0;
  if (!args.parse(argc - 1, argv + 1, exit_code)) return exit_code;
  const double minutes = args.number("minutes");
  const std::string edge = args.get("edge");
  if (edge != "latest" && edge != "blocking") {
    std::cerr << "mocap-soak: --edge must be latest or blocking\n";
    return 2;
  }
  const std::string video = fs::absolute(args.get("video")).string();
  if (!fs::exists(video)) {
    std::cerr << "mocap-soak: no video " << video << "\n";
    return 2;
  }
  std::unique_ptr<mocap::test::TempDir> temp;
  fs::path dir;
  if (args.has("keep")) {
    dir = args.get("keep");
    fs::create_directories(dir);
  } else {
    temp = std::make_unique<mocap::test::TempDir>();
    dir = temp->path();
  }
  const std::string probe = (dir / "probe.txt").string();
  const std::string graph = (dir / "soak.yaml").string();
  mocap::test::write_file(
      graph, graph_text(video, edge, args.number("delay-ms"), mocap::test::free_tcp_port(), probe));
  std::cout << "# mocap-soak: " << edge << " edge, " << minutes << " min, " << video
            << ", consumer " << args.get("delay-ms") << " ms per frame\n\n"
            << "graph: " << graph << "\n\n";

  mocap::test::ChildProcess run(args.get("mocap"), {"run", graph, "--max-restarts", "0"},
                                (dir / "run.out").string(), (dir / "run.err").string(),
                                mocap::test::environment("MOCAP_"));
  std::map<std::string, int> pids{{"supervisor", run.pid()}};
  const std::regex started(R"(started group '(\w+)' \(pid (\d+)\))");
  ProbeReader reader(probe);
  std::vector<Minute> table;
  Minute current;
  std::vector<double> latencies;
  std::uint64_t next_seq = 0, repeats = 0;
  const auto sample_every = std::chrono::duration<double>(args.number("sample-s"));
  const auto start = Clock::now();
  const auto end = start + std::chrono::duration<double>(minutes * 60.0);
  auto next_minute = start + 60s;
  std::cout << "| minute | messages | drops | RSS supervisor MiB | RSS capture MiB | RSS solve MiB "
               "| latency p50 ms | latency p95 ms |\n|---:|---:|---:|---:|---:|---:|---:|---:|\n"
            << std::flush;
  auto print_row = [&](std::size_t index, const Minute& m) {
    std::printf("| %zu | %lu | %lu | %.1f | %.1f | %.1f | %.1f | %.1f |\n", index + 1, m.messages,
                m.drops, m.rss.count("supervisor") ? m.rss.at("supervisor") : -1.0,
                m.rss.count("capture") ? m.rss.at("capture") : -1.0,
                m.rss.count("solve") ? m.rss.at("solve") : -1.0, m.p50_ms, m.p95_ms);
    std::fflush(stdout);
  };
  bool died = false;
  while (Clock::now() < end) {
    std::this_thread::sleep_for(sample_every);
    const std::string err = run.err();
    for (auto it = std::sregex_iterator(err.begin(), err.end(), started);
         it != std::sregex_iterator(); ++it) {
      pids[(*it)[1].str()] = std::stoi((*it)[2].str());
    }
    for (const auto& [name, pid] : pids) current.rss[name] = rss_mib(pid);
    for (const ProbeReader::Line& line : reader.next()) {
      ++current.messages;
      latencies.push_back(line.latency_us / 1000.0);
      if (line.seq >= next_seq) {
        current.drops += line.seq - next_seq;
        next_seq = line.seq + 1;
      } else {
        ++repeats;
      }
    }
    if (Clock::now() >= next_minute || Clock::now() >= end) {
      current.p50_ms = percentile(latencies, 50);
      current.p95_ms = percentile(latencies, 95);
      print_row(table.size(), current);
      table.push_back(current);
      current = Minute{};
      latencies.clear();
      next_minute += 60s;
    }
    if (rss_mib(run.pid()) < 0 || err.find("restarting") != std::string::npos ||
        err.find("gave up") != std::string::npos) {
      died = true;
      break;
    }
  }

  // Stop it as an operator would, and time the exit.
  const auto stop_sent = Clock::now();
  kill(run.pid(), SIGTERM);
  const std::optional<int> code = run.wait(30s);
  const double stop_s = std::chrono::duration<double>(Clock::now() - stop_sent).count();
  std::uint64_t tail = 0;
  for (const ProbeReader::Line& line : reader.next()) {
    ++tail;
    if (line.seq >= next_seq) {
      table.back().drops += line.seq - next_seq;  // counted in the last minute
      next_seq = line.seq + 1;
    } else {
      ++repeats;
    }
  }
  const std::string err = run.err();

  std::printf("\nstop: SIGTERM -> exit %s in %.2f s; %lu messages arrived after the last row\n",
              code ? std::to_string(*code).c_str() : "none (killed after 30 s)", stop_s, tail);
  std::printf(
      "\n| process | RSS after minute 1 MiB | RSS at the end MiB | change MiB |\n"
      "|---|---:|---:|---:|\n");
  bool flat = table.size() >= 2;
  for (const char* name : {"supervisor", "capture", "solve"}) {
    if (table.size() < 2 || !table.front().rss.count(name)) continue;
    const double first = table.front().rss.at(name), last = table.back().rss.at(name);
    std::printf("| %s | %.1f | %.1f | %+.1f |\n", name, first, last, last - first);
    flat = flat && last - first < 5.0;
  }
  double worst_p95 = 0, first_p95 = table.empty() ? 0 : table.front().p95_ms;
  std::uint64_t messages = 0, drops = 0;
  for (const Minute& m : table) {
    worst_p95 = std::max(worst_p95, m.p95_ms);
    messages += m.messages;
    drops += m.drops;
  }
  messages += tail;

  // What the programs themselves said: the source's count, the probe's check, the runtime's drops.
  std::smatch match;
  std::uint64_t sent = 0;
  if (std::regex_search(err, match, std::regex(R"(src: (\d+) frames sent, (\d+) skipped)")))
    sent = std::stoull(match[1]);
  std::printf("\nfrom the programs' logs (%s):\n", (dir / "run.err").c_str());
  for (const std::regex& re :
       {std::regex(R"(src: \d+ frames sent.*)"), std::regex(R"(test.probe 'probe': .*)"),
        std::regex(R"(slow\s+test.delay\s+.*)"), std::regex(R"(src\s+source.video\s+.*)"),
        std::regex(R"(edge .*missed.*)")}) {
    if (std::regex_search(err, match, re)) std::printf("  %s\n", match[0].str().c_str());
  }
  std::uint64_t runtime_drops = 0;
  if (std::regex_search(err, match, std::regex(R"(slow\s+test.delay\s+\d+\s+\d+\s+(\d+))")))
    runtime_drops = std::stoull(match[1]);

  std::printf(
      "\nmessages %lu, drops by sequence number %lu, drops in the runtime's statistics "
      "%lu, repeated or out of order %lu, source sent %lu, last seq + 1 = %lu\n",
      messages, drops, runtime_drops, repeats, sent, next_seq);
  std::printf("latency p95: first minute %.1f ms, worst minute %.1f ms\n", first_p95, worst_p95);
  // Latest: a stop is quick. Blocking: the messages already queued are processed first (nothing
  // is lost), about queue length x consumer time; the exit code says whether it drained.
  const bool quick_stop = edge == "blocking" || stop_s < 2.0;
  bool ok = !died && code && *code == 0 && quick_stop && repeats == 0 && flat;
  if (edge == "blocking") {
    const bool lossless = drops == 0 && sent > 0 && messages == sent && next_seq == sent;
    std::printf(
        "blocking loss check: every sequence number 0..%lu arrived exactly once, in "
        "order: %s\n",
        sent == 0 ? 0 : sent - 1, lossless ? "yes" : "NO");
    ok = ok && lossless;
  } else {
    // Drops: every sequence number missing at the probe is a drop the runtime counted.
    ok = ok && drops == runtime_drops;
  }
  std::printf("\nverdict: %s%s%s%s\n", ok ? "PASS" : "FAIL", died ? " (a process died)" : "",
              flat ? " (memory flat within 5 MiB after minute 1)" : " (memory grew)",
              quick_stop ? "" : " (slow stop)");
  return ok ? 0 : 1;
}
