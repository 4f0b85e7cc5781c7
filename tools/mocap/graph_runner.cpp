#include "graph_runner.hpp"

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>
#include <thread>

#include "core/input_error.hpp"
#include "graph/signals.hpp"

namespace mocap::cli {
namespace {

// Signals may arrive before the runtime exists; the request is kept until it does.
class StopRelay {
 public:
  void attach(graph::Runtime* runtime) {
    std::lock_guard lock(mutex_);
    runtime_ = runtime;
    if (runtime_ && requested_) runtime_->request_stop();
  }
  void request() {
    std::lock_guard lock(mutex_);
    requested_ = true;
    if (runtime_) runtime_->request_stop();
  }

 private:
  std::mutex mutex_;
  graph::Runtime* runtime_ = nullptr;
  bool requested_ = false;
};

// Empty when a listening socket could bind `host`:`port` (as the web server does, with
// SO_REUSEADDR), else why not.
std::string bind_problem(const std::string& host, int port) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int error = getaddrinfo(host.c_str(), service.c_str(), &hints, &found); error != 0)
    return std::string("cannot resolve the address: ") + gai_strerror(error);
  std::string problem = "no address";
  for (addrinfo* a = found; a; a = a->ai_next) {
    const int fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      problem = std::strerror(errno);
      continue;
    }
    const int yes = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    const bool bound = bind(fd, a->ai_addr, a->ai_addrlen) == 0;
    problem = bound ? std::string() : std::strerror(errno);
    close(fd);
    if (bound) break;
  }
  freeaddrinfo(found);
  return problem;
}

}  // namespace

void check_ports_free(const graph::ResolvedGraph& graph, const graph::RunOptions& options) {
  for (const graph::ResolvedNode& node : graph.nodes) {
    if (!options.single_process && !options.process.empty() && node.process != options.process)
      continue;
    const std::string& host_param = node.type->contract.http_host_param();
    const auto host = node.params.find(host_param);
    const auto port = node.params.find("port");
    if (host_param.empty() || host == node.params.end() || port == node.params.end()) continue;
    const auto* host_text = std::get_if<std::string>(&host->second);
    const auto* port_number = std::get_if<std::int64_t>(&port->second);
    if (!host_text || !port_number || *port_number == 0) continue;
    const std::string problem = bind_problem(*host_text, static_cast<int>(*port_number));
    if (!problem.empty()) {
      throw InputError(node.name, "cannot serve on " + *host_text + ":" +
                                      std::to_string(*port_number) + ": " + problem +
                                      " (another program, or another mocap, listens there? "
                                      "choose another port, or 0 for a free one)");
    }
  }
}

graph::RunResult run_graph_here(const graph::ResolvedGraph& graph, graph::RunOptions options,
                                const std::string& label, const ProgressCallback& progress,
                                std::chrono::milliseconds every) {
  // A file over the size limit (`ulimit -f`) makes the write fail with EFBIG, which the sink
  // reports naming the file, instead of SIGXFSZ ending the process without a word.
  std::signal(SIGXFSZ, SIG_IGN);
  check_ports_free(graph, options);
  StopRelay relay;
  graph::SignalWatcher watcher([&](int, int count) {
    if (count > 1) {
      std::cerr << label << ": second stop signal, exiting without draining\n";
      std::_Exit(130);
    }
    std::cerr << label << ": stopping: draining the graph (signal again to exit at once)\n";
    relay.request();
  });
  const bool one_group = !options.process.empty();
  graph::Runtime runtime(graph, std::move(options));
  relay.attach(&runtime);
  std::mutex done_mutex;
  std::condition_variable done_changed;
  bool done = false;
  std::thread reporter;
  if (progress) {
    reporter = std::thread([&] {
      std::unique_lock lock(done_mutex);
      while (!done_changed.wait_for(lock, every, [&] { return done; })) progress(runtime.stats());
    });
  }
  // A supervised group says when it is up, so its supervisor's log (and tests) can tell a group
  // that is still starting from one that runs.
  if (one_group) std::cerr << label << ": running\n";
  graph::RunResult result = runtime.run();
  if (reporter.joinable()) {
    {
      const std::lock_guard lock(done_mutex);
      done = true;
    }
    done_changed.notify_all();
    reporter.join();
  }
  relay.attach(nullptr);
  return result;
}

}  // namespace mocap::cli
