#pragma once
// SIGINT / SIGTERM handling without a signal handler or global state: the signals are blocked in
// every thread and one watcher thread collects them with sigtimedwait, then calls back on an
// ordinary thread where locks and condition variables are allowed.

#include <atomic>
#include <functional>
#include <thread>

namespace mocap::graph {

class SignalWatcher {
 public:
  // Create it before any other thread: threads inherit the blocked signal mask.
  // `on_signal` receives the signal number and how many stop signals came so far (1, 2, ...).
  explicit SignalWatcher(std::function<void(int signal, int count)> on_signal);
  ~SignalWatcher();
  SignalWatcher(const SignalWatcher&) = delete;
  SignalWatcher& operator=(const SignalWatcher&) = delete;

 private:
  std::function<void(int, int)> on_signal_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

}  // namespace mocap::graph
