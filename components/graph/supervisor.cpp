#include "graph/supervisor.hpp"

#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <thread>

extern char** environ;

namespace mocap::graph {

using Clock = std::chrono::steady_clock;

struct Child {
  std::string group;
  pid_t pid = -1;
  int restarts = 0;
  bool finished = false;
  Clock::time_point restart_at{};
};

struct Supervisor::Impl {
  SupervisorOptions options;
  std::vector<Child> children;
  std::atomic<bool> stop_requested{false};
  bool failed = false;

  void log(const std::string& message) const {
    if (options.log) {
      options.log(message);
    } else {
      std::cerr << "supervisor: " << message << "\n";
    }
  }

  pid_t spawn(const std::string& group) const {
    std::vector<std::string> args{options.program};
    args.insert(args.end(), options.args.begin(), options.args.end());
    args.insert(args.end(), {"--process", group});
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    std::vector<std::string> env_strings;
    for (char** e = environ; *e; ++e) {
      if (std::strncmp(*e, kSupervisorPidVariable, std::strlen(kSupervisorPidVariable)) != 0) {
        env_strings.emplace_back(*e);
      }
    }
    env_strings.push_back(std::string(kSupervisorPidVariable) + "=" + std::to_string(getpid()));
    std::vector<char*> envp;
    for (auto& e : env_strings) envp.push_back(e.data());
    envp.push_back(nullptr);

    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    // The group starts with the stop signals blocked and at their default action: a SIGTERM
    // that arrives while it is still loading its libraries stays pending until its signal
    // watcher takes it, instead of killing it before it can drain.
    sigset_t stop_signals, defaults;
    sigemptyset(&stop_signals);
    sigaddset(&stop_signals, SIGINT);
    sigaddset(&stop_signals, SIGTERM);
    defaults = stop_signals;
    posix_spawnattr_setsigmask(&attr, &stop_signals);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setpgroup(&attr, 0);
    posix_spawnattr_setflags(
        &attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETPGROUP);
    pid_t pid = -1;
    const int error =
        posix_spawn(&pid, options.program.c_str(), nullptr, &attr, argv.data(), envp.data());
    posix_spawnattr_destroy(&attr);
    if (error != 0) {
      log("cannot start group '" + group + "': " + std::strerror(error));
      return -1;
    }
    log("started group '" + group + "' (pid " + std::to_string(pid) + ")");
    return pid;
  }

  void signal_all(int signal) const {
    for (const Child& c : children) {
      if (c.pid > 0) kill(c.pid, signal);
    }
  }

  void on_exit(Child& child, int status) {
    child.pid = -1;
    const bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    const std::string how = WIFSIGNALED(status)
                                ? "killed by signal " + std::to_string(WTERMSIG(status))
                                : "exited with " + std::to_string(WEXITSTATUS(status));
    if (clean) {
      child.finished = true;
      log("group '" + child.group + "' finished");
      return;
    }
    if (stop_requested) {
      child.finished = true;
      failed = true;
      log("group '" + child.group + "' " + how + " while stopping");
      return;
    }
    if (child.restarts >= options.max_restarts) {
      child.finished = true;
      failed = true;
      log("group '" + child.group + "' " + how + "; gave up after " +
          std::to_string(child.restarts) + " restarts");
      stop_requested = true;
      return;
    }
    const auto backoff =
        std::chrono::milliseconds(std::min(5000, 200 << std::min(child.restarts, 5)));
    ++child.restarts;
    child.restart_at = Clock::now() + backoff;
    log("group '" + child.group + "' " + how + "; restarting in " +
        std::to_string(backoff.count()) + " ms (restart " + std::to_string(child.restarts) +
        " of " + std::to_string(options.max_restarts) + ")");
  }
};

Supervisor::Supervisor(std::vector<std::string> groups, SupervisorOptions options)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  for (auto& g : groups) impl_->children.push_back(Child{std::move(g)});
}

Supervisor::~Supervisor() {
  // Never leave children behind, whatever happened.
  impl_->signal_all(SIGKILL);
  for (const Child& c : impl_->children) {
    if (c.pid > 0) waitpid(c.pid, nullptr, 0);
  }
}

void Supervisor::request_stop() { impl_->stop_requested = true; }

int Supervisor::run() {
  Impl& s = *impl_;
  for (Child& c : s.children) {
    c.pid = s.spawn(c.group);
    if (c.pid < 0) {
      s.failed = true;
      s.stop_requested = true;
      c.finished = true;
    }
  }
  bool terminated = false;
  Clock::time_point stop_since{};
  while (true) {
    int status = 0;
    for (pid_t pid = waitpid(-1, &status, WNOHANG); pid > 0; pid = waitpid(-1, &status, WNOHANG)) {
      for (Child& c : s.children) {
        if (c.pid == pid) s.on_exit(c, status);
      }
    }
    if (s.stop_requested && !terminated) {
      terminated = true;
      stop_since = Clock::now();
      s.signal_all(SIGTERM);
    }
    if (terminated && Clock::now() - stop_since > s.options.stop_grace) {
      s.log("groups still running " + std::to_string(s.options.stop_grace.count()) +
            " ms after SIGTERM: killing them");
      s.signal_all(SIGKILL);
      s.failed = true;
    }
    bool all_finished = true;
    for (Child& c : s.children) {
      if (!c.finished && c.pid < 0 && !s.stop_requested && Clock::now() >= c.restart_at) {
        c.pid = s.spawn(c.group);
      }
      if (!c.finished && c.pid < 0 && s.stop_requested)
        c.finished = true;  // pending restart cancelled
      all_finished = all_finished && c.finished;
    }
    if (all_finished) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return s.failed ? 1 : 0;
}

bool follow_supervisor() {
  const char* value = std::getenv(kSupervisorPidVariable);
  if (!value) return true;
  prctl(PR_SET_PDEATHSIG, SIGTERM);
  return getppid() == static_cast<pid_t>(std::atol(value));
}

}  // namespace mocap::graph
