// sink.vmc against a real OSC receiver on loopback (a liblo server thread): every frame arrives as
// one bundle with the VMC messages, the humanoid bone names, unit quaternions and a root on the
// floor with the hips above it, at the rate the frames come in; all_people uses successive ports.

#include <lo/lo.h>
#include <cstring>

#include <chrono>
#include <cmath>
#include <iostream>
#include <mutex>
#include <set>
#include <thread>

#include "export/humanoid.hpp"
#include "sink_test_util.hpp"
#include "support/small_pose_database.hpp"

namespace mocap::nodes {
namespace {

using testing::run_graph;
using Clock = std::chrono::steady_clock;

struct OscMessage {
  std::string path, types, name;
  std::vector<float> values;
  int bundle = -1;
};

// A liblo server thread on a free UDP port (or the one asked for) that keeps every message.
class OscReceiver {
 public:
  explicit OscReceiver(int port = 0) {
    thread_ = lo_server_thread_new(port ? std::to_string(port).c_str() : nullptr, nullptr);
    if (!thread_) return;
    lo_server_thread_add_method(thread_, nullptr, nullptr, &OscReceiver::on_message, this);
    lo_server_add_bundle_handlers(lo_server_thread_get_server(thread_), &OscReceiver::on_start,
                                  &OscReceiver::on_end, this);
    lo_server_thread_start(thread_);
  }
  ~OscReceiver() {
    if (thread_) {
      lo_server_thread_stop(thread_);
      lo_server_thread_free(thread_);
    }
  }
  OscReceiver(const OscReceiver&) = delete;
  OscReceiver& operator=(const OscReceiver&) = delete;

  bool ok() const { return thread_ != nullptr; }
  int port() const { return lo_server_thread_get_port(thread_); }

  // Waits until `bundles` bundles are in or nothing came for `quiet`.
  void wait_for(std::size_t bundles,
                std::chrono::milliseconds quiet = std::chrono::milliseconds(500)) {
    std::size_t last = 0;
    auto since = Clock::now();
    while (Clock::now() - since < quiet) {
      const std::size_t now = bundle_count();
      if (now >= bundles) return;
      if (now != last) last = now, since = Clock::now();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  std::size_t bundle_count() const {
    std::lock_guard lock(mutex_);
    return bundle_times_.size();
  }
  std::vector<OscMessage> messages() const {
    std::lock_guard lock(mutex_);
    return messages_;
  }
  std::vector<Clock::time_point> bundle_times() const {
    std::lock_guard lock(mutex_);
    return bundle_times_;
  }

 private:
  static int on_start(lo_timetag, void* self) {
    auto* r = static_cast<OscReceiver*>(self);
    std::lock_guard lock(r->mutex_);
    r->bundle_times_.push_back(Clock::now());
    r->in_bundle_ = true;
    return 0;
  }
  static int on_end(void* self) {
    auto* r = static_cast<OscReceiver*>(self);
    std::lock_guard lock(r->mutex_);
    r->in_bundle_ = false;
    return 0;
  }
  static int on_message(const char* path, const char* types, lo_arg** argv, int argc, lo_message,
                        void* self) {
    auto* r = static_cast<OscReceiver*>(self);
    OscMessage m;
    m.path = path;
    m.types = types;
    for (int i = 0; i < argc; ++i) {
      if (types[i] == 's') m.name = &argv[i]->s;
      // liblo's arguments point into the packet, not always aligned for lo_arg: copy the bytes.
      if (types[i] == 'f') {
        float f = 0;
        std::memcpy(&f, argv[i], sizeof f);
        m.values.push_back(f);
      }
      if (types[i] == 'i') {
        std::int32_t v = 0;
        std::memcpy(&v, argv[i], sizeof v);
        m.values.push_back(static_cast<float>(v));
      }
    }
    std::lock_guard lock(r->mutex_);
    m.bundle = r->in_bundle_ ? static_cast<int>(r->bundle_times_.size()) - 1 : -1;
    r->messages_.push_back(std::move(m));
    return 0;
  }

  lo_server_thread thread_ = nullptr;
  mutable std::mutex mutex_;
  bool in_bundle_ = false;
  std::vector<OscMessage> messages_;
  std::vector<Clock::time_point> bundle_times_;
};

std::string vmc_graph(const std::string& db, const std::string& script, const std::string& params,
                      double interval_ms = 0.0) {
  return R"(
nodes:
  src: { type: unit.people_script, params: { db: )" +
         db + ", script: \"" + script + "\", interval_ms: " + std::to_string(interval_ms) +
         R"( } }
  vmc: { type: sink.vmc, params: { )" +
         params + R"( } }
edges:
  - [src.people3d, vmc.in]
)";
}

// `frames` frames of person 3 (CMU clip 0 through view 4) and, from frame 5, person 5 (clip 1).
std::string script(int frames) {
  std::string s;
  for (int f = 0; f < frames; ++f) {
    if (f) s += ';';
    s += "3:0:" + std::to_string(f % 100) + ":4";
    if (f >= 5) s += ",5:1:" + std::to_string(f % 100) + ":2";
  }
  return s;
}

// Checks one bundle's messages.
// The script source stamps frame k as captured at 1 s + k x 40 ms: /VMC/Ext/T follows that.
constexpr double kCaptureStep_s = 0.040;

void expect_vmc_bundle(const std::vector<OscMessage>& bundle, int index) {
  ASSERT_EQ(bundle.size(), 3u + exporting::kHumanBones) << "bundle " << index;
  EXPECT_EQ(bundle[0].path, "/VMC/Ext/OK");
  EXPECT_EQ(bundle[0].types, "i");
  EXPECT_EQ(bundle[1].path, "/VMC/Ext/T");
  ASSERT_EQ(bundle[1].values.size(), 1u);
  EXPECT_NEAR(bundle[1].values[0], index * kCaptureStep_s, 1e-4) << "bundle " << index;
  EXPECT_EQ(bundle[2].path, "/VMC/Ext/Root/Pos");
  EXPECT_EQ(bundle[2].name, "root");
  std::set<std::string> bones;
  for (std::size_t i = 2; i < bundle.size(); ++i) {
    const OscMessage& m = bundle[i];
    EXPECT_EQ(m.types, "sfffffff") << m.path;
    ASSERT_EQ(m.values.size(), 7u);
    const float norm = std::sqrt(m.values[3] * m.values[3] + m.values[4] * m.values[4] +
                                 m.values[5] * m.values[5] + m.values[6] * m.values[6]);
    EXPECT_NEAR(norm, 1.0f, 1e-4f) << m.name;
    if (i >= 3) {
      EXPECT_EQ(m.path, "/VMC/Ext/Bone/Pos");
      bones.insert(m.name);
    }
  }
  // The root on the floor, near the origin (the people are not placed); the hips above it.
  EXPECT_NEAR(bundle[2].values[1], 0.0f, 1e-6f);
  EXPECT_LT(std::abs(bundle[2].values[0]) + std::abs(bundle[2].values[2]), 0.01f);
  EXPECT_EQ(bundle[3].name, "Hips");
  EXPECT_GT(bundle[3].values[1], 0.6f);
  EXPECT_LT(bundle[3].values[1], 1.3f);
  std::set<std::string> expected(exporting::kHumanBoneNames.begin(),
                                 exporting::kHumanBoneNames.end());
  EXPECT_EQ(bones, expected);
}

std::vector<std::vector<OscMessage>> by_bundle(const std::vector<OscMessage>& messages) {
  std::vector<std::vector<OscMessage>> out;
  for (const OscMessage& m : messages) {
    if (m.bundle < 0) {
      ADD_FAILURE() << "message outside a bundle: " << m.path;
      continue;
    }
    if (static_cast<std::size_t>(m.bundle) >= out.size()) out.resize(m.bundle + 1);
    out[m.bundle].push_back(m);
  }
  return out;
}

TEST(VmcSink, EveryFrameIsOneBundleOfHumanoidBones) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  OscReceiver receiver;
  ASSERT_TRUE(receiver.ok()) << "no UDP port for the receiver";
  const int frames = 60;
  const graph::RunResult result = run_graph(
      vmc_graph(db, script(frames), "port: " + std::to_string(receiver.port()) + ", fps: 24"));
  ASSERT_TRUE(result.ok) << result.error;
  receiver.wait_for(frames);
  const auto bundles = by_bundle(receiver.messages());
  ASSERT_EQ(bundles.size(), static_cast<std::size_t>(frames));
  for (int b = 0; b < frames; ++b) expect_vmc_bundle(bundles[b], b);
  // Different poses along the clip: the left upper arm turns.
  auto arm = [&](int b) {
    for (const OscMessage& m : bundles[b])
      if (m.name == "LeftUpperArm") return m.values;
    return std::vector<float>{};
  };
  EXPECT_NE(arm(0), arm(frames - 1));
}

TEST(VmcSink, SendsAtTheRateTheFramesComeIn) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  OscReceiver receiver;
  ASSERT_TRUE(receiver.ok());
  const int frames = 45;
  const auto start = Clock::now();
  const graph::RunResult result = run_graph(vmc_graph(
      db, script(frames), "port: " + std::to_string(receiver.port()) + ", fps: 30", 1000.0 / 30));
  ASSERT_TRUE(result.ok) << result.error;
  receiver.wait_for(frames);
  const double run_s = std::chrono::duration<double>(Clock::now() - start).count();
  const std::vector<Clock::time_point> times = receiver.bundle_times();
  ASSERT_EQ(times.size(), static_cast<std::size_t>(frames));
  const double span = std::chrono::duration<double>(times.back() - times.front()).count();
  const double rate = (frames - 1) / span;
  const std::size_t messages = receiver.messages().size();
  std::cout << "[ note ] paced at 30 fps: " << frames << " bundles, " << messages
            << " messages received in " << span << " s: " << rate << " bundles/s, "
            << rate * (3 + exporting::kHumanBones) << " messages/s (run " << run_s << " s)\n";
  EXPECT_NEAR(rate, 30.0, 6.0);  // the source paces by sleeping: a loaded machine is slower
}

TEST(VmcSink, UnpacedThroughput) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  OscReceiver receiver;
  ASSERT_TRUE(receiver.ok());
  const int frames = 600;
  const auto start = Clock::now();
  const graph::RunResult result = run_graph(
      vmc_graph(db, script(frames), "port: " + std::to_string(receiver.port()) + ", fps: 30"));
  ASSERT_TRUE(result.ok) << result.error;
  const double run_s = std::chrono::duration<double>(Clock::now() - start).count();
  receiver.wait_for(frames);
  const std::size_t bundles = receiver.bundle_count();
  const std::size_t messages = receiver.messages().size();
  std::cout << "[ note ] unpaced: " << frames << " frames sent in " << run_s << " s ("
            << frames * (3 + exporting::kHumanBones) / run_s << " messages/s, whole graph); "
            << bundles << " bundles, " << messages << " messages received\n";
  // A measurement, not a requirement: UDP drops whole datagrams when the receiver's socket
  // buffer (about 200 KB by default) fills, as it does when 600 bundles of 1.7 KB come at once.
  // What arrives must be whole bundles.
  EXPECT_GT(bundles, 0u);
  EXPECT_EQ(messages, bundles * (3 + exporting::kHumanBones));
}

TEST(VmcSink, AllPeopleGoToSuccessivePorts) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  // Two receivers on neighbouring ports: take a free one, then try the next.
  std::unique_ptr<OscReceiver> first, second;
  for (int attempt = 0; attempt < 20 && !second; ++attempt) {
    first = std::make_unique<OscReceiver>();
    ASSERT_TRUE(first->ok());
    second = std::make_unique<OscReceiver>(first->port() + 1);
    if (!second->ok()) second.reset();
  }
  ASSERT_TRUE(second) << "no two neighbouring free UDP ports";
  const int frames = 20;
  const graph::RunResult result = run_graph(vmc_graph(
      db, script(frames), "port: " + std::to_string(first->port()) + ", all_people: true"));
  ASSERT_TRUE(result.ok) << result.error;
  first->wait_for(frames);
  second->wait_for(frames - 5);
  EXPECT_EQ(first->bundle_count(), static_cast<std::size_t>(frames));       // person 3
  EXPECT_EQ(second->bundle_count(), static_cast<std::size_t>(frames - 5));  // person 5 from frame 5
}

// One port: person 3 in frames 0-9, nobody in 10-39, person 5 in 40-49. Person 3 has been gone
// 1.24 s when person 5 comes (40 ms per frame): with release_s 1 person 5 gets the port, with 10
// it is not sent.
TEST(VmcSink, APortIsGivenToTheNextPersonAfterReleaseTime) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  std::string s;
  for (int f = 0; f < 50; ++f) {
    if (f) s += ';';
    if (f < 10) s += "3:0:" + std::to_string(f) + ":4";
    if (f >= 40) s += "5:1:" + std::to_string(f) + ":2";
  }
  for (const auto& [release, expected] : {std::pair{"1", 20u}, std::pair{"10", 10u}}) {
    OscReceiver receiver;
    ASSERT_TRUE(receiver.ok());
    const graph::RunResult result =
        run_graph(vmc_graph(db, s,
                            "port: " + std::to_string(receiver.port()) +
                                ", all_people: true, max_people: 1, release_s: " + release));
    ASSERT_TRUE(result.ok) << result.error;
    receiver.wait_for(expected);
    EXPECT_EQ(receiver.bundle_count(), expected) << "release_s " << release;
  }
}

// person: an id sends that person only (person 5 is in frames 5-19); first keeps person 3.
TEST(VmcSink, PersonChoiceByIdAndFirst) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  for (const auto& [choice, expected] : {std::pair{"5", 15u}, std::pair{"first", 20u}}) {
    OscReceiver receiver;
    ASSERT_TRUE(receiver.ok());
    const graph::RunResult result = run_graph(vmc_graph(
        db, script(20), "port: " + std::to_string(receiver.port()) + ", person: " + choice));
    ASSERT_TRUE(result.ok) << result.error;
    receiver.wait_for(expected);
    EXPECT_EQ(receiver.bundle_count(), expected) << "person " << choice;
  }
}

TEST(VmcSink, UnknownPersonChoiceIsRefusedNamingTheNode) {
  MOCAP_REQUIRE_SMALL_DATABASE(db);
  const graph::RunResult result = run_graph(vmc_graph(db, "1:0:0:0", "person: tallest"));
  EXPECT_FALSE(result.ok);
  EXPECT_NE(result.error.find("tallest"), std::string::npos) << result.error;
}

}  // namespace
}  // namespace mocap::nodes
