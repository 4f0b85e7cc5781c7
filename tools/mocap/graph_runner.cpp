#include "graph_runner.hpp"

#include <condition_variable>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <mutex>
#include <thread>

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

}  // namespace

graph::RunResult run_graph_here(const graph::ResolvedGraph& graph, graph::RunOptions options,
                                const std::string& label, const ProgressCallback& progress,
                                std::chrono::milliseconds every) {
  // A file over the size limit (`ulimit -f`) makes the write fail with EFBIG, which the sink
  // reports naming the file, instead of SIGXFSZ ending the process without a word.
  std::signal(SIGXFSZ, SIG_IGN);
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
