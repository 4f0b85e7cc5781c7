// mocap_aravis against Aravis' own fake GigE Vision camera, run as a child process on loopback.
// Skipped, saying why, when aravis-tools is not installed. Timings are checked loosely: the
// machine is shared.

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <thread>

#include "camera.hpp"
#include "fake_gv_camera.hpp"
#include "reconnecting_camera.hpp"

namespace mocap::aravis {
namespace {

using namespace std::chrono_literals;
using test::FakeGvCamera;

class FakeCameraTest : public test::FakeCameraFixture {
 protected:
  std::unique_ptr<FakeGvCamera> start(int loss_per_thousand = 0) {
    return std::make_unique<FakeGvCamera>(*program_, test::unique_serial("MOCAP"),
                                          loss_per_thousand);
  }
  static CameraSettings mono8(const std::string& id, double fps) {
    CameraSettings s;
    s.id = id;
    s.region = Region{0, 0, 512, 512};
    s.frame_rate = fps;
    s.pixel_format = "Mono8";
    return s;
  }
  static std::vector<Frame> grab(Camera& camera, int n) {
    std::vector<Frame> frames;
    for (int i = 0; i < 4 * n && static_cast<int>(frames.size()) < n; ++i) {
      if (auto f = camera.next(2s)) frames.push_back(std::move(*f));
    }
    return frames;
  }
};

// GigE Vision 1 block ids are 16 bits, counting 1..65535 and wrapping.
bool follows(std::uint64_t previous, std::uint64_t id) {
  return id == previous + 1 || (previous == 65535 && id <= 1);
}

TEST_F(FakeCameraTest, ListsTheFakeCamera) {
  const auto camera = start();
  const auto devices = list_devices();
  const auto it = std::find_if(devices.begin(), devices.end(),
                               [&](const DeviceInfo& d) { return d.serial == camera->serial(); });
  ASSERT_NE(it, devices.end());
  EXPECT_EQ(it->vendor, "Aravis");
  EXPECT_EQ(it->model, "Fake");
  EXPECT_EQ(it->address, "127.0.0.1");
  EXPECT_EQ(it->protocol, "GigEVision");
  EXPECT_FALSE(it->id.empty());
}

TEST_F(FakeCameraTest, GrabsMono8WithMonotonicTimestampsAndFrameIds) {
  const auto fake = start();
  Camera camera(mono8(fake->serial(), 50));
  EXPECT_EQ(camera.pixel_format(), "Mono8");
  EXPECT_EQ(camera.info().serial, fake->serial());
  const auto frames = grab(camera, 10);
  ASSERT_EQ(frames.size(), 10u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].image.width(), 512);
    EXPECT_EQ(frames[i].image.height(), 512);
    EXPECT_EQ(frames[i].image.format(), PixelFormat::gray8);
    EXPECT_GT(frames[i].capture_ns, 0);
    if (i == 0) continue;
    EXPECT_GT(frames[i].device_ns, frames[i - 1].device_ns);
    EXPECT_GT(frames[i].capture_ns, frames[i - 1].capture_ns);
    EXPECT_TRUE(follows(frames[i - 1].frame_id, frames[i].frame_id))
        << frames[i - 1].frame_id << " then " << frames[i].frame_id;
  }
  // capture time is device time moved onto CLOCK_REALTIME: never after the frame arrived.
  EXPECT_LE(frames.back().capture_ns, frames.back().system_ns);
  EXPECT_EQ(camera.counters().delivered, 10u);
}

TEST_F(FakeCameraTest, BayerAndRgbArriveAsRgb8) {
  const auto fake = start();
  for (const std::string format : {"BayerRG8", "BayerGB8", "RGB8"}) {
    CameraSettings s = mono8(fake->serial(), 30);
    s.pixel_format = format;
    s.region = Region{0, 0, 320, 240};
    Camera camera(s);
    EXPECT_EQ(camera.pixel_format(), format);
    const auto frames = grab(camera, 2);
    ASSERT_EQ(frames.size(), 2u) << format;
    EXPECT_EQ(frames[0].image.format(), PixelFormat::rgb8) << format;
    EXPECT_EQ(frames[0].image.width(), 320) << format;
    EXPECT_EQ(frames[0].image.height(), 240) << format;
  }
}

// Loose on purpose: the fake camera is a process on this shared machine and stamps frames with
// the time it sends them, so a busy machine slows it down. A camera set 4x faster must still be
// clearly faster, and neither may exceed its setting by much.
TEST_F(FakeCameraTest, AchievedRateFollowsTheSetting) {
  const auto fake = start();
  std::vector<double> rates;
  for (const double fps : {20.0, 80.0}) {
    Camera camera(mono8(fake->serial(), fps));
    EXPECT_NEAR(camera.frame_rate(), fps, 0.5);
    const auto frames = grab(camera, 20);
    ASSERT_EQ(frames.size(), 20u);
    const double rate =
        19e9 / static_cast<double>(frames.back().device_ns - frames.front().device_ns);
    EXPECT_LT(rate, 1.2 * fps);
    EXPECT_GT(rate, 0.3 * fps);
    rates.push_back(rate);
  }
  EXPECT_GT(rates[1], 2 * rates[0]) << "20 fps: " << rates[0] << ", 80 fps: " << rates[1];
}

TEST_F(FakeCameraTest, PacketLossIsCountedAndNeverDelivered) {
  const auto fake = start(/*loss_per_thousand=*/30);
  Camera camera(mono8(fake->serial(), 50));
  int delivered = 0;
  const auto deadline = std::chrono::steady_clock::now() + 4s;
  while (std::chrono::steady_clock::now() < deadline) {
    if (const auto f = camera.next(500ms)) {
      ++delivered;
      EXPECT_EQ(f->image.size_bytes(), 512u * 512u);
    }
  }
  const StreamCounters counters = camera.counters();
  EXPECT_EQ(counters.delivered, static_cast<std::uint64_t>(delivered));
  EXPECT_GT(counters.incomplete + counters.skipped_ids, 0u)
      << "delivered " << delivered << " with 3% of the packets lost";
}

TEST_F(FakeCameraTest, AnUnknownCameraIsNamedInTheError) {
  try {
    Camera camera(mono8("no-such-camera-4711", 25));
    FAIL() << "opened a camera that does not exist";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-camera-4711"), std::string::npos) << e.what();
  }
}

// The fake camera's only deep format: Mono16 arrives as gray8, its high bytes (the fake camera
// writes the same ramp as in Mono8, scaled to 16 bits, so the two images agree closely).
TEST_F(FakeCameraTest, Mono16ArrivesAsItsHighByte) {
  const auto fake = start();
  CameraSettings s = mono8(fake->serial(), 25);
  s.region = Region{0, 0, 64, 48};
  s.pixel_format = "Mono16";
  Camera camera(s);
  EXPECT_EQ(camera.pixel_format(), "Mono16");
  const auto frames = grab(camera, 2);
  ASSERT_EQ(frames.size(), 2u);
  const ImageBuffer& image = frames[1].image;
  EXPECT_EQ(image.format(), PixelFormat::gray8);
  EXPECT_EQ(image.width(), 64);
  EXPECT_EQ(image.height(), 48);
  int lowest = 255, highest = 0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const int v =
          static_cast<int>(image.data()[static_cast<std::size_t>(y) * image.stride() + x]);
      lowest = std::min(lowest, v);
      highest = std::max(highest, v);
    }
  }
  EXPECT_LT(lowest, highest) << "a flat image: the high bytes were not taken";
}

// A camera another client controls cannot stream: the second opener is told so, by name.
TEST_F(FakeCameraTest, ACameraControlledElsewhereIsReported) {
  const auto fake = start();
  Camera first(mono8(fake->serial(), 25));
  try {
    Camera second(mono8(fake->serial(), 25));
    FAIL() << "two controllers of one camera";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot take control"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(fake->serial()), std::string::npos) << e.what();
  }
  EXPECT_TRUE(first.next(2s)) << "the first controller keeps streaming";
}

// Filling frames with a test's own pixels is for Aravis' in-process fake camera only.
TEST_F(FakeCameraTest, AFillFunctionIsRefusedForOtherCameras) {
  const auto fake = start();
  CameraSettings s = mono8(fake->serial(), 25);
  s.fake_fill = [](std::span<std::byte>, int, int) {};
  try {
    Camera camera(s);
    FAIL() << "a GigE camera accepted a fill function";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("in-process fake"), std::string::npos) << e.what();
  }
}

// How long a dead camera goes unnoticed: with Aravis' heartbeat alone (loss_timeout 0), and with
// the stream watchdog (1 s at 25 fps). Both times are printed for the record.
double seconds_until_lost(Camera& camera, std::chrono::seconds limit) {
  const auto start = std::chrono::steady_clock::now();
  while (!camera.control_lost() && std::chrono::steady_clock::now() - start < limit)
    camera.next(200ms);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST_F(FakeCameraTest, ControlLostIsSeenWhenTheCameraDies) {
  auto fake = start();
  CameraSettings s = mono8(fake->serial(), 25);
  s.loss_timeout = 0ms;  // the heartbeat only
  auto camera = std::make_unique<Camera>(s);
  ASSERT_TRUE(camera->next(2s));
  fake->stop();
  const double seconds = seconds_until_lost(*camera, 30s);
  std::cout << "[ measured ] heartbeat only: lost after " << seconds << " s\n";
  RecordProperty("heartbeat_loss_s", std::to_string(seconds));
  EXPECT_TRUE(camera->control_lost());
  EXPECT_NE(camera->loss_reason().find("heartbeat"), std::string::npos) << camera->loss_reason();
  EXPECT_FALSE(camera->next(100ms));
  const auto start = std::chrono::steady_clock::now();
  camera.reset();
  std::cout << "[ measured ] closing the lost camera: "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s\n";
}

TEST_F(FakeCameraTest, TheStreamWatchdogSeesADeadCameraWithinItsTimeout) {
  auto fake = start();
  CameraSettings s = mono8(fake->serial(), 25);
  s.loss_timeout = 1000ms;
  auto camera = std::make_unique<Camera>(s);
  ASSERT_TRUE(camera->next(2s));
  ASSERT_TRUE(camera->next(2s));
  EXPECT_FALSE(camera->control_lost()) << camera->loss_reason();
  fake->stop();
  const double seconds = seconds_until_lost(*camera, 30s);
  std::cout << "[ measured ] stream watchdog (1000 ms): lost after " << seconds << " s\n";
  RecordProperty("watchdog_loss_s", std::to_string(seconds));
  ASSERT_TRUE(camera->control_lost());
  EXPECT_NE(camera->loss_reason().find("no data for"), std::string::npos) << camera->loss_reason();
  EXPECT_LT(seconds, 3.0);  // 1 s of silence, measured from the last frame, plus slack
  EXPECT_FALSE(camera->next(100ms));
  // Closing it waits for Aravis' own timeouts (its heartbeat thread, the GVCP writes of leaving
  // control): source.aravis therefore closes a lost camera on another thread.
  const auto start = std::chrono::steady_clock::now();
  camera.reset();
  const double closing =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "[ measured ] closing the lost camera: " << closing << " s\n";
}

// A healthy camera is never declared lost by the watchdog, even at a timeout shorter than its
// frame period would allow (the watchdog waits at least 10 periods).
TEST_F(FakeCameraTest, TheWatchdogLeavesASlowHealthyCameraAlone) {
  const auto fake = start();
  CameraSettings s = mono8(fake->serial(), 5);  // 200 ms per frame
  s.loss_timeout = 100ms;
  Camera camera(s);
  const auto frames = grab(camera, 8);
  EXPECT_EQ(frames.size(), 8u);
  EXPECT_FALSE(camera.control_lost()) << camera.loss_reason();
}

// The camera dies and comes back with the same serial: ReconnectingCamera reports the loss once,
// reopens it, and counts losses and reconnections across both connections.
TEST_F(FakeCameraTest, AReconnectingCameraReopensACameraThatComesBack) {
  const std::string serial = test::unique_serial("RECON");
  auto fake = std::make_unique<FakeGvCamera>(*program_, serial);
  CameraSettings s = mono8(serial, 25);
  s.loss_timeout = 1000ms;
  ReconnectingCamera camera(s);
  EXPECT_NE(camera.description().find(serial), std::string::npos) << camera.description();
  EXPECT_NE(camera.status().find("streaming from"), std::string::npos) << camera.status();
  const auto frames_until = [&](int wanted, std::chrono::seconds limit, std::string& news) {
    int frames = 0;
    const auto end = std::chrono::steady_clock::now() + limit;
    while (frames < wanted && std::chrono::steady_clock::now() < end) {
      Poll poll = camera.poll(200ms);
      if (!poll.news.empty()) news += poll.news + "\n";
      if (poll.away) std::this_thread::sleep_for(200ms);
      frames += poll.frame ? 1 : 0;
    }
    return frames;
  };
  std::string news;
  ASSERT_EQ(frames_until(3, 15s, news), 3);
  EXPECT_EQ(news, "");
  fake.reset();  // killed: the watchdog sees no data, the camera is lost
  const auto end = std::chrono::steady_clock::now() + 30s;
  while (camera.totals().losses == 0 && std::chrono::steady_clock::now() < end) {
    Poll poll = camera.poll(200ms);
    if (!poll.news.empty()) news += poll.news + "\n";
  }
  ASSERT_EQ(camera.totals().losses, 1u) << news;
  EXPECT_NE(news.find("lost (no data for"), std::string::npos) << news;
  EXPECT_NE(camera.status().find("[1 lost, 0 reconnects]"), std::string::npos) << camera.status();
  fake = std::make_unique<FakeGvCamera>(*program_, serial);
  EXPECT_EQ(frames_until(3, 60s, news), 3) << news;
  EXPECT_NE(news.find("reconnected to camera '"), std::string::npos) << news;
  EXPECT_EQ(camera.totals().reconnects, 1u);
  EXPECT_NE(camera.status().find("[1 lost, 1 reconnects]"), std::string::npos) << camera.status();
}

}  // namespace
}  // namespace mocap::aravis
