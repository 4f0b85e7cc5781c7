#pragma once
// Aravis' fake GigE Vision camera (`arv-fake-gv-camera-0.8`, package aravis-tools) as a child
// process on loopback. Every wait is bounded; the camera is killed and reaped when the object goes
// away, and dies with the test process (PR_SET_PDEATHSIG) should the test crash.

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "camera.hpp"

namespace mocap::test {

inline constexpr const char* kFakeCameraProgram = "arv-fake-gv-camera-0.8";

// The program's path on PATH, or nullopt (the tests then skip, saying why).
inline std::optional<std::string> fake_camera_program() {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const auto candidate = std::filesystem::path(dir) / kFakeCameraProgram;
    if (!dir.empty() && access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return std::nullopt;
}

// The fake camera's control port (UDP 3956 on 127.0.0.1) admits one camera per host, and other
// test runs on the same machine (other build folders, other checkouts) start theirs too: a test
// holds this host-wide lock for its whole length. flock is released when the process ends, however
// it ends.
class FakeCameraLock {
 public:
  explicit FakeCameraLock(std::chrono::seconds timeout = std::chrono::seconds(150)) {
    fd_ = open("/tmp/mocap-arv-fake-gv-camera.lock", O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd_ < 0) throw std::runtime_error("cannot open the fake camera lock file");
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      if (std::chrono::steady_clock::now() > deadline) {
        close(fd_);
        throw std::runtime_error("another test run kept the fake camera for too long");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  ~FakeCameraLock() { close(fd_); }
  FakeCameraLock(const FakeCameraLock&) = delete;
  FakeCameraLock& operator=(const FakeCameraLock&) = delete;

 private:
  int fd_ = -1;
};

class FakeGvCamera {
 public:
  // Starts the camera with this serial (and `loss_per_thousand` GVSP packets dropped) on this
  // interface address and waits until Aravis discovers it. Throws when it does not appear within
  // `timeout`. One camera per address (private_loopback.hpp gives loopback more).
  FakeGvCamera(const std::string& program, std::string serial, int loss_per_thousand = 0,
               std::chrono::milliseconds timeout = std::chrono::seconds(15),
               const std::string& address = "127.0.0.1")
      : serial_(std::move(serial)) {
    std::vector<std::string> args = {program, "-i", address, "-s", serial_};
    if (loss_per_thousand > 0) {
      args.push_back("-r");
      args.push_back(std::to_string(loss_per_thousand));
    }
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_ = fork();
    if (pid_ == 0) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      const int devnull = open("/dev/null", O_WRONLY);
      dup2(devnull, 1);
      dup2(devnull, 2);
      execv(argv[0], argv.data());
      _exit(127);
    }
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (!wait_until_discovered(timeout)) {
      stop();
      throw std::runtime_error("the fake camera " + serial_ + " did not appear on " + address);
    }
  }
  ~FakeGvCamera() { stop(); }
  FakeGvCamera(const FakeGvCamera&) = delete;
  FakeGvCamera& operator=(const FakeGvCamera&) = delete;

  const std::string& serial() const { return serial_; }

  void stop() {
    if (pid_ <= 0) return;
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  bool wait_until_discovered(std::chrono::milliseconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      for (const auto& device : aravis::list_devices()) {
        if (device.serial == serial_) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }

  std::string serial_;
  pid_t pid_ = -1;
};

// A serial no other test process uses at the same time.
inline std::string unique_serial(const std::string& prefix) {
  return prefix + std::to_string(getpid());
}

// Base of every test that runs the fake GigE camera program: skips, saying why, when it is not
// installed, and holds the host-wide FakeCameraLock for the test's duration.
class FakeCameraFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    program_ = fake_camera_program();
    if (!program_) GTEST_SKIP() << kFakeCameraProgram << " not on PATH (package aravis-tools)";
    lock_.emplace();
  }
  std::optional<std::string> program_;
  std::optional<FakeCameraLock> lock_;
};

}  // namespace mocap::test
