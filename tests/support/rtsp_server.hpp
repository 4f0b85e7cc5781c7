#pragma once
// A real RTSP server for tests: tests/support/rtsp_server.py (GStreamer's gst-rtsp-server, run by
// Debian's /usr/bin/python3) serving a video file as live H.264 on a free loopback port, one
// mount per name. Tests skip with problem() when it cannot start (packages absent: see
// tools/setup.sh). Killed (SIGKILL: a server that goes away without a word) by stop() or when
// the object goes away.

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "support/files.hpp"
#include "support/mocap_process.hpp"

namespace mocap::test {

inline constexpr const char* kRtspServerScript = "tests/support/rtsp_server.py";
inline constexpr const char* kSystemPython = "/usr/bin/python3";  // has python3-gi

struct RtspServerOptions {
  std::string video;                             // the file served
  std::vector<std::string> mounts = {"stream"};  // rtsp://127.0.0.1:PORT/<mount>
  int width = 0, height = 0;                     // scaled to this size (0: the video's)
  int frames = 0;                                // the first N frames only (0: all)
  double fps = 0.0;                              // 0: the video's rate
  bool loop = false;                             // start again at the end (else the stream ends)
  int port = 0;                                  // 0: a free one
};

class RtspServer {
 public:
  RtspServer(const TempDir& dir, const std::string& name, const RtspServerOptions& o) {
    if (!std::filesystem::exists(kSystemPython)) {
      problem_ = std::string(kSystemPython) + " is absent";
      return;
    }
    std::vector<std::string> args = {kRtspServerScript, "--video", o.video};
    for (const std::string& m : o.mounts) args.insert(args.end(), {"--mount", m});
    if (o.width > 0)
      args.insert(args.end(),
                  {"--width", std::to_string(o.width), "--height", std::to_string(o.height)});
    if (o.frames > 0) args.insert(args.end(), {"--frames", std::to_string(o.frames)});
    if (o.fps > 0) args.insert(args.end(), {"--fps", std::to_string(o.fps)});
    if (o.loop) args.push_back("--loop");
    if (o.port > 0) args.insert(args.end(), {"--port", std::to_string(o.port)});
    out_ = dir.file(name + ".out");
    process_.emplace(kSystemPython, args, out_, dir.file(name + ".err"), environment());
    wait_until_ready(o.mounts);
  }

  // Why the server is not serving (empty when it is).
  const std::string& problem() const { return problem_; }
  std::string url(const std::string& mount = "stream") const { return base_ + "/" + mount; }
  std::string log() const { return process_ ? process_->out() + process_->err() : ""; }
  // Kills the server: its clients see the stream stop without an end.
  void stop() { process_.reset(); }

 private:
  // It decodes the video before it listens: seconds under load (and GStreamer scans its plugins
  // the first time it runs).
  void wait_until_ready(const std::vector<std::string>& mounts) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      for (const std::string& line : read_lines(out_)) {
        if (line.rfind("ready ", 0) == 0) base_ = line.substr(6);
        if (line.rfind("error: ", 0) == 0) problem_ = "the RTSP server did not start: " + line;
      }
      // Every mount line printed, or a failure.
      if (!problem_.empty()) break;
      if (!base_.empty() && read_lines(out_).size() >= 1 + mounts.size()) return;
      if (const auto code = process_->wait(std::chrono::milliseconds(50))) {
        problem_ = "the RTSP server exited (" + std::to_string(*code) + "): " + log();
        break;
      }
    }
    if (problem_.empty()) problem_ = "the RTSP server did not start within 60 s: " + log();
    process_.reset();
  }

  std::optional<ChildProcess> process_;
  std::string out_, base_, problem_;
};

}  // namespace mocap::test
