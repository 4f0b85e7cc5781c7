#pragma once
// A camera that is reopened with the same settings whenever it comes back after it stopped
// answering (no data for loss_timeout, or Aravis' heartbeat failed), with frame and drop counts
// that go on across the reconnections. What source.aravis needs, without the framework.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "camera.hpp"

namespace mocap::aravis {

// Totals over the whole capture, every reconnection included.
struct CaptureTotals {
  std::uint64_t incomplete = 0;  // buffers that arrived with missing packets, timeouts, ...
  std::uint64_t skipped = 0;     // frames never seen (gaps in the frame ids)
  std::uint64_t losses = 0;      // times the camera stopped answering
  std::uint64_t reconnects = 0;  // times it was opened again
};

// What one poll brought.
struct Poll {
  std::optional<Frame> frame;
  std::uint64_t new_drops = 0;  // incomplete or never-seen frames since the previous poll
  std::string news;             // the camera was lost or reopened ("" : nothing happened)
  bool away = false;            // lost and not reopened yet: wait a little before polling again
};

class ReconnectingCamera {
 public:
  // Opens the camera; throws std::runtime_error naming it (and the setting) on failure.
  explicit ReconnectingCamera(CameraSettings settings);
  ~ReconnectingCamera();
  ReconnectingCamera(const ReconnectingCamera&) = delete;
  ReconnectingCamera& operator=(const ReconnectingCamera&) = delete;

  // Waits up to `timeout` for the next complete frame; while the camera is away, one attempt to
  // reopen it instead.
  Poll poll(std::chrono::milliseconds timeout);

  // "camera 'ID' (WxH FORMAT, F fps, B buffers)" of the camera now open ("" while away).
  std::string description() const;
  // The status line: what happened last, with the loss and reconnection counts.
  std::string status() const { return status_; }
  const CaptureTotals& totals() const { return totals_; }

 private:
  Poll lose(Poll poll);
  Poll reconnect();
  void count_drops(Poll& poll);

  CameraSettings settings_;
  std::unique_ptr<Camera> camera_;
  std::string id_;  // the camera's id, kept while it is away
  CaptureTotals totals_;
  std::uint64_t seen_drops_ = 0;  // drops of the current connection already reported
  std::uint64_t base_incomplete_ = 0, base_skipped_ = 0;  // totals of the earlier connections
  std::string status_;
  // Closing a camera that no longer answers waits for Aravis' timeouts (5 to 10 s on GigE): it
  // happens on its own thread, so the reconnection attempts start at once. Joined on destruction.
  std::vector<std::jthread> closing_;
};

}  // namespace mocap::aravis
