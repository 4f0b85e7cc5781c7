#pragma once
// GigE Vision and USB3 Vision cameras through Aravis 0.8: discovery, settings, a stream with a
// buffer pool, and complete frames converted to ImageBuffer. Aravis and GLib stay inside
// camera.cpp (pimpl), so including this header pulls in neither.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/image_buffer.hpp"

namespace mocap::aravis {

struct DeviceInfo {
  std::string id;  // what Camera accepts: Aravis' device id ("vendor-model-serial" style)
  std::string vendor, model, serial, address, protocol;
};

// Every camera Aravis sees now (discovery broadcasts on every interface, loopback included).
std::vector<DeviceInfo> list_devices();

struct Region {
  int x = 0, y = 0, width = 0, height = 0;
};

struct CameraSettings {
  std::string id;                // device id, serial or address; empty: the first camera found
  std::optional<Region> region;  // none: the camera's current region
  double frame_rate = 0;         // frames per second; 0: leave the camera's setting
  double exposure_us = 0;        // microseconds; 0: leave it
  std::optional<double> gain;    // none: leave it
  std::string pixel_format;      // GenICam name (Mono8, BayerRG8, ...); empty: leave it
  int buffers = 0;               // stream buffers; 0: half a second of frames (4..64)
  // No buffer at all (whole or not) for this long, once streaming: the camera counts as lost, as
  // when its heartbeat fails, but sooner (Aravis' heartbeat notices a dead GigE camera after 6 s).
  // At least 10 frame periods; the first frame may take 2 s more. 0: only the heartbeat.
  std::chrono::milliseconds loss_timeout{0};
  // Only for Aravis' in-process fake camera (enable_fake_interface): writes the pixels of every
  // frame, on Aravis' streaming thread, so tests can send their own images through the camera
  // path. Opening any other camera with it set fails.
  std::function<void(std::span<std::byte> pixels, int width, int height)> fake_fill;
  // Only for the in-process fake camera: a PFNC code written straight into its pixel format
  // register (its GenICam file lists Mono8, Mono16, Bayer*8 and RGB8 only), so that tests can
  // stream the other formats (YUV422, Mono12p, ...) end to end. 0: not used.
  std::uint32_t fake_pixel_format = 0;
};

struct Frame {
  ImageBuffer image;
  std::uint64_t frame_id = 0;   // the camera's block id
  std::int64_t device_ns = 0;   // the camera's timestamp (its own clock)
  std::int64_t system_ns = 0;   // when the host received it (CLOCK_REALTIME)
  std::int64_t capture_ns = 0;  // device time mapped to CLOCK_REALTIME (see Camera::next)
};

struct StreamCounters {
  std::uint64_t delivered = 0;    // complete frames returned by next()
  std::uint64_t incomplete = 0;   // buffers that arrived with missing packets, timeouts, ...
  std::uint64_t skipped_ids = 0;  // gaps in the frame ids: frames never seen at all
  std::uint64_t underruns = 0;    // frames the stream had no free buffer for
};

class Camera {
 public:
  // Opens the camera, applies the settings, creates the stream and starts acquisition. Throws
  // std::runtime_error naming the camera (and the setting) on failure.
  explicit Camera(const CameraSettings& settings);
  ~Camera();
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;

  // The next complete frame, or nullopt after `timeout` (or once control is lost). Incomplete
  // buffers are counted and skipped, never returned. capture_ns is the device timestamp plus the
  // smallest (arrival - device) offset seen so far: the device clock keeps the spacing of frames
  // exact and the minimum offset is the arrival with the least transport delay.
  std::optional<Frame> next(std::chrono::milliseconds timeout);

  // The camera stopped answering: its heartbeat failed, or nothing arrived for loss_timeout.
  bool control_lost() const;
  std::string loss_reason() const;  // why control_lost() is true ("" while it is not)
  StreamCounters counters() const;
  const DeviceInfo& info() const;
  std::string pixel_format() const;  // the camera's GenICam name of its current format
  double frame_rate() const;         // as the camera reports it
  Region region() const;
  int buffer_count() const;
  std::vector<std::string> available_pixel_formats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Aravis' in-process fake camera (interface "Fake"): enabled once per process, for tests.
void enable_fake_interface();

}  // namespace mocap::aravis
