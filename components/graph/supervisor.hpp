#pragma once
// Runs every process group of a graph as a child process (`mocap run GRAPH --process NAME`) and
// restarts a group that dies (killed, crashed, non-zero exit) with a growing back-off. A group
// that exits 0 has finished. Children run in their own process group so that a terminal's Ctrl-C
// reaches only the supervisor, which forwards one SIGTERM so they drain in order; they also ask the
// kernel for SIGTERM should the supervisor die first, so no process is ever left behind.

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mocap::graph {

struct SupervisorOptions {
  std::string program;            // the mocap executable
  std::vector<std::string> args;  // before "--process NAME": e.g. {"run", graph, "--set", ...}
  int max_restarts = 5;           // per group; then the whole graph stops with an error
  std::chrono::milliseconds stop_grace{10000};  // after SIGTERM, then SIGKILL
  std::function<void(const std::string&)> log;
};

class Supervisor {
 public:
  Supervisor(std::vector<std::string> groups, SupervisorOptions options);
  ~Supervisor();
  // Returns 0 when every group finished cleanly, 1 otherwise.
  int run();
  void request_stop();  // thread-safe

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// Environment variable set for children: the supervisor's pid.
inline constexpr const char* kSupervisorPidVariable = "MOCAP_SUPERVISOR_PID";
// Called early by a child: exit with the supervisor (PR_SET_PDEATHSIG). Returns false when the
// supervisor is already gone.
bool follow_supervisor();

}  // namespace mocap::graph
