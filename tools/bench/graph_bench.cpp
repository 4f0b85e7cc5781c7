// mocap-bench-graph: throughput and latency of one edge per transport (in-process queue, and
// ZeroMQ over inproc://, ipc://, tcp://127.0.0.1 plain and with CURVE) for small messages (one
// person, COCO-17) and 1920x1080 RGB frames. Prints a Markdown table.
//
// Throughput: a producer thread sends as fast as a blocking(16) edge lets it. Latency: one
// message at a time (the next leaves when the previous arrived), send to receive, one way.
// A second table: the synchroniser of joined inputs alone (graph/synchronizer.hpp), sets per
// second for 2 to 16 inputs, in order or with one input 100 frames late, in one thread.

#include <unistd.h>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <thread>

#include "cli_args.hpp"
#include "graph/inbox.hpp"
#include "graph/stats.hpp"
#include "graph/synchronizer.hpp"
#include "graph/transport.hpp"

namespace {

using namespace mocap;
using namespace mocap::graph;
using Clock = std::chrono::steady_clock;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

// One edge, whatever carries it: send() on one thread, receive() on another.
struct Edge {
  std::function<void(Packet)> send;
  std::function<Packet()> receive;
};

struct Payload {
  std::string name;
  std::function<Packet(std::uint64_t seq)> make;  // stamps capture_ns with the send time
  double megabytes = 0;
};

Payload small_payload() {
  return {"People2D, 1 person",
          [](std::uint64_t seq) {
            auto m = std::make_shared<People2D>();
            m->header = {"bench", seq, now_ns(), 0};
            Person2D person;
            person.joints.resize(17, Keypoint2D{1, 2, 0.5f});
            m->people.push_back(std::move(person));
            return Packet::of<People2D>(m);
          },
          0};
}

Payload frame_payload() {
  auto image = ImageBuffer(1920, 1080, PixelFormat::rgb8);  // shared by every message: no refill
  return {"VideoFrame 1920x1080 RGB",
          [image](std::uint64_t seq) {
            auto m = std::make_shared<VideoFrame>();
            m->header = {"bench", seq, now_ns(), 0};
            m->image = image;
            return Packet::of<VideoFrame>(m);
          },
          static_cast<double>(image.size_bytes()) / 1e6};
}

struct Result {
  double per_second = 0, p50_us = 0, p99_us = 0;
};

Result measure(Edge& edge, const Payload& payload, int throughput_count, int latency_count) {
  Result result;
  // Throughput: pipelined.
  std::thread producer([&] {
    for (int i = 0; i < throughput_count; ++i)
      edge.send(payload.make(static_cast<std::uint64_t>(i)));
  });
  const auto start = Clock::now();
  for (int i = 0; i < throughput_count; ++i) edge.receive();
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  producer.join();
  result.per_second = throughput_count / seconds;
  // Latency: one message in flight.
  std::vector<std::int64_t> latencies;
  std::atomic<int> received{0};
  std::thread paced([&] {
    for (int i = 0; i < latency_count; ++i) {
      edge.send(payload.make(static_cast<std::uint64_t>(i)));
      while (received.load() <= i) std::this_thread::yield();
    }
  });
  for (int i = 0; i < latency_count; ++i) {
    const Packet packet = edge.receive();
    latencies.push_back(now_ns() - packet.header().capture_ns);
    received = i + 1;
  }
  paced.join();
  result.p50_us = percentile(latencies, 50) / 1000.0;
  result.p99_us = percentile(latencies, 99) / 1000.0;
  return result;
}

Edge in_process_edge(Inbox& inbox) {
  return {[&inbox](Packet p) { inbox.push(0, std::move(p)); },
          [&inbox] { return inbox.pop()->packet; }};
}

Edge zeromq_edge(Sender& sender, Receiver& receiver) {
  return {[&sender](Packet p) { sender.send(p); },
          [&receiver] {
            while (true) {
              auto result = receiver.receive(std::chrono::milliseconds(1000));
              if (result.message) return std::move(result.message->packet);
              if (!result.rejected.empty()) throw std::runtime_error(result.rejected);
            }
          }};
}

void print_row(const std::string& transport, const Payload& payload, const Result& r) {
  char line[256];
  const double mb_per_s = payload.megabytes * r.per_second;
  std::snprintf(line, sizeof line, "| %-12s | %-26s | %12.0f | %9s | %10.1f | %10.1f |\n",
                transport.c_str(), payload.name.c_str(), r.per_second,
                payload.megabytes > 0 ? std::to_string(static_cast<long>(mb_per_s)).c_str() : "-",
                r.p50_us, r.p99_us);
  std::cout << line << std::flush;
}

// Sets per second through a synchroniser of `inputs` inputs: every input sends frames 0..sets-1;
// with `lag`, input 0 runs `lag` frames ahead of the others (held meanwhile).
double sync_sets_per_second(std::size_t inputs, int sets, int lag) {
  Synchronizer sync(inputs, {SyncKey::frame, 0, std::chrono::nanoseconds(0),
                             static_cast<std::size_t>(lag + 16), AtBound::pass_partial});
  std::vector<Packet> messages;  // made beforehand: the table measures the joining only
  for (int f = 0; f < sets; ++f) {
    auto m = std::make_shared<People2D>();
    m->header.frame = f;
    messages.push_back(Packet::of<People2D>(std::move(m)));
  }
  SyncSet set;
  std::uint64_t passed = 0;
  const auto start = Clock::now();
  for (int f = 0; f < sets + lag; ++f) {
    const auto now = Clock::now();
    if (f < sets) sync.push(0, messages[static_cast<std::size_t>(f)], now);
    if (f >= lag) {
      for (std::size_t i = 1; i < inputs; ++i) {
        sync.push(i, messages[static_cast<std::size_t>(f - lag)], now);
      }
    }
    while (sync.pop(now, set)) passed += set.complete() ? 1 : 0;
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (passed != static_cast<std::uint64_t>(sets)) throw std::logic_error("incomplete sets");
  return sets / seconds;
}

}  // namespace

int main(int argc, char** argv) {
  mocap::cli::Args args("mocap-bench-graph [--small N] [--frames N] [--sets N]",
                        "Throughput and one-way latency of one graph edge per transport, and "
                        "sets per second through the synchroniser of joined inputs.");
  args.option("small", "N", "small messages per throughput run", "20000")
      .option("frames", "N", "1920x1080 frames per throughput run", "300")
      .option("sets", "N", "sets per synchroniser run", "200000");
  int exit_code = 0;
  if (!args.parse(argc - 1, argv + 1, exit_code)) return exit_code;
  const int small = static_cast<int>(args.integer("small"));
  const int frames = static_cast<int>(args.integer("frames"));

  const std::string ipc_dir =
      (std::filesystem::temp_directory_path() / ("mocap-bench-" + std::to_string(getpid())))
          .string();
  std::filesystem::create_directories(ipc_dir);
  std::cout << "| transport    | message                    | messages/s   | MB/s      | p50 µs    "
               " | p99 µs     |\n"
               "|--------------|----------------------------|-------------:|----------:|-----------"
               ":|-----------:|\n";
  const Payload payloads[] = {small_payload(), frame_payload()};
  for (const Payload& payload : payloads) {
    const bool is_frame = payload.megabytes > 0;
    const int count = is_frame ? frames : small;
    const int latency_count = is_frame ? std::min(frames, 200) : std::min(small, 2000);
    {
      Inbox inbox({EdgePolicy{PolicyKind::blocking, 16}});
      Edge edge = in_process_edge(inbox);
      print_row("in-process", payload, measure(edge, payload, count, latency_count));
    }
    int port = 5790;
    for (const std::string kind : {"inproc", "ipc", "tcp", "tcp+curve"}) {
      const std::string endpoint = kind == "inproc" ? "inproc://bench"
                                   : kind == "ipc"  ? "ipc://" + ipc_dir + "/edge"
                                                    : "tcp://127.0.0.1:" + std::to_string(port++);
      // tcp+curve: the same edge encrypted and authenticated with CURVE (docs/security.md).
      SocketOptions server, client;
      if (kind == "tcp+curve") {
        const CurveKeyPair server_keys = generate_curve_key_pair();
        const CurveKeyPair client_keys = generate_curve_key_pair();
        server.curve = {server_keys.secret_key, {}, {client_keys.public_key}};
        client.curve = {client_keys.secret_key, server_keys.public_key, {}};
      }
      TransportContext context;
      Receiver receiver(context, endpoint, server);
      Sender sender(context, endpoint, Sender::Pattern::edge, client);
      Edge edge = zeromq_edge(sender, receiver);
      print_row(kind, payload, measure(edge, payload, count, latency_count));
    }
  }
  std::filesystem::remove_all(ipc_dir);

  const int sets = static_cast<int>(args.integer("sets"));
  std::cout << "\n| joined inputs | arrival                    | sets/s       | ns per set |\n"
               "|--------------:|----------------------------|-------------:|-----------:|\n";
  for (const std::size_t inputs : {2u, 4u, 16u}) {
    for (const int lag : {0, 100}) {
      const double rate = sync_sets_per_second(inputs, sets, lag);
      char line[160];
      std::snprintf(line, sizeof line, "| %13zu | %-26s | %12.0f | %10.0f |\n", inputs,
                    lag ? "others 100 frames late" : "in step", rate, 1e9 / rate);
      std::cout << line << std::flush;
    }
  }
  return 0;
}
