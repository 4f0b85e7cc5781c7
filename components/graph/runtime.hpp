#pragma once
// Runs a validated graph: one thread per node, bounded queues with per-edge policies between
// nodes in this process, ZeroMQ edges to other processes, end of stream propagated through every
// edge, statistics per node. Stopping (a signal, a failed node) drains: sources stop, every
// message already sent is processed, sinks close and flush.

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "graph/stats.hpp"
#include "graph/validation.hpp"

namespace mocap::graph {

struct RunOptions {
  std::string process;          // run only this process group; empty: every node
  bool single_process = false;  // ignore transports: every edge in-process
  // After a stop request, how long the graph drains: queued messages are processed, an edge from
  // another process waits for its end of stream and a send for a full peer, until this passes;
  // then what is still queued is counted and logged, not processed (so SIGTERM exits within 2 s).
  std::chrono::milliseconds drain_timeout{1500};
  std::function<void(const std::string&)> log;  // warnings; stderr when empty
};

struct RunResult {
  bool ok = true;
  std::string error;     // names the failed node: "node 'det' (detect.movenet) failed: ..."
  bool stopped = false;  // a stop was requested before the graph ended by itself
  GraphStats stats;
};

class Runtime {
 public:
  // Creates the nodes and binds/connects every ZeroMQ edge; throws std::runtime_error when an
  // endpoint cannot be used or the process group is unknown.
  explicit Runtime(const ResolvedGraph& graph, RunOptions options = {});
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  // Runs until every node has finished; call once.
  RunResult run();
  // Thread-safe and async-signal-unsafe (call it from a normal thread): sources stop and the
  // graph drains.
  void request_stop();
  GraphStats stats() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::graph
