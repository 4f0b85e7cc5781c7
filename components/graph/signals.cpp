#include "graph/signals.hpp"

#include <pthread.h>
#include <signal.h>

namespace mocap::graph {

namespace {
sigset_t stop_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}
}  // namespace

SignalWatcher::SignalWatcher(std::function<void(int, int)> on_signal)
    : on_signal_(std::move(on_signal)) {
  const sigset_t set = stop_signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  thread_ = std::thread([this] {
    const sigset_t watched = stop_signals();
    const timespec slice{0, 100'000'000};
    int count = 0;
    while (!done_) {
      const int signal = sigtimedwait(&watched, nullptr, &slice);
      if (signal > 0) on_signal_(signal, ++count);
    }
  });
}

// The signals stay blocked: the process is about to end, and a late signal must not kill it
// while it flushes.
SignalWatcher::~SignalWatcher() {
  done_ = true;
  thread_.join();
}

}  // namespace mocap::graph
