#pragma once
// Child processes for tests: the built `mocap` binary (MOCAP_BINARY, defined by the test target) or
// any program, with stdout and stderr in files; every wait is bounded and the child is killed and
// reaped when the object goes away.

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <cstring>
#include <optional>
#include <regex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "support/files.hpp"

extern char** environ;

namespace mocap::test {

using namespace std::chrono_literals;

// A child process running `program ARGS...` with the given environment, stdout and stderr going
// to files; killed and reaped when the object goes away.
class ChildProcess {
 public:
  ChildProcess(const std::string& program, std::vector<std::string> args, std::string out,
               std::string err, std::vector<std::string> env)
      : out_(std::move(out)), err_(std::move(err)) {
    args.insert(args.begin(), program);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<char*> envp;
    for (auto& e : env) envp.push_back(e.data());
    envp.push_back(nullptr);
    posix_spawn_file_actions_t files;
    posix_spawn_file_actions_init(&files);
    posix_spawn_file_actions_addopen(&files, 1, out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&files, 2, err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int error =
        posix_spawn(&pid_, program.c_str(), &files, nullptr, argv.data(), envp.data());
    posix_spawn_file_actions_destroy(&files);
    if (error != 0)
      throw std::runtime_error("cannot start " + program + ": " + std::strerror(error));
  }
  ~ChildProcess() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);  // a mocap's children follow (PR_SET_PDEATHSIG)
      waitpid(pid_, nullptr, 0);
    }
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  // The exit code (128 + signal when killed), or nullopt after `timeout` (the process is killed).
  std::optional<int> wait(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(20ms);
    }
    return std::nullopt;
  }
  std::string err() const { return read_file(err_); }
  std::string out() const { return read_file(out_); }

 protected:
  std::string out_, err_;
  pid_t pid_ = -1;
};

// This process's environment, less the variables whose names start with `drop` (if given).
inline std::vector<std::string> environment(const std::string& drop = "") {
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e) {
    if (drop.empty() || std::strncmp(*e, drop.c_str(), drop.size()) != 0) env.emplace_back(*e);
  }
  return env;
}

// A child process running the built `mocap ARGS...` (no inherited MOCAP_* plugin path).
class Mocap : public ChildProcess {
 public:
  Mocap(const TempDir& dir, const std::string& name, std::vector<std::string> args,
        std::vector<std::string> extra_env = {})
      : ChildProcess(MOCAP_BINARY, std::move(args), dir.file(name + ".out"),
                     dir.file(name + ".err"), with(environment("MOCAP_"), extra_env)) {}

  // Waits until the process has `signal` blocked (the graph's signal watcher takes stop signals
  // with sigtimedwait): a signal sent before that would kill it with the default action.
  bool wait_until_blocking(int signal, std::chrono::milliseconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    const std::string status = "/proc/" + std::to_string(pid_) + "/status";
    while (std::chrono::steady_clock::now() < deadline) {
      for (const std::string& line : read_lines(status)) {
        if (line.rfind("SigBlk:", 0) != 0) continue;
        const unsigned long long mask = std::stoull(line.substr(7), nullptr, 16);
        if (mask & (1ull << (signal - 1))) return true;
      }
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }
  // Waits until stderr matches `pattern`; returns the first capture group (or "").
  std::optional<std::string> wait_for_log(const std::string& pattern,
                                          std::chrono::milliseconds timeout,
                                          std::size_t occurrence = 1) const {
    const std::regex re(pattern);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      const std::string text = err();
      std::size_t seen = 0;
      for (auto it = std::sregex_iterator(text.begin(), text.end(), re);
           it != std::sregex_iterator(); ++it) {
        if (++seen == occurrence) return it->size() > 1 ? (*it)[1].str() : std::string();
      }
      std::this_thread::sleep_for(20ms);
    }
    return std::nullopt;
  }

 private:
  static std::vector<std::string> with(std::vector<std::string> env,
                                       const std::vector<std::string>& extra) {
    env.insert(env.end(), extra.begin(), extra.end());
    return env;
  }
};

}  // namespace mocap::test
