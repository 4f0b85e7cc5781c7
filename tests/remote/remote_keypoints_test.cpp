// source.remote_keypoints in the real `mocap` binary, fed by the real Python client
// (tools/remote/send_keypoints.py, python3-zmq): the keypoints that come out of the graph (through
// sink.publish) are the ones the C++ OpenPose reader finds in the same files, and garbage sent to
// the node first (random bytes, truncated, wrong version, oversized counts, wrong type or joint
// count) is counted and named with its sender, while the graph goes on. Skips, saying why, when
// python3 or its zmq module is missing.

#include <gtest/gtest.h>
#include <unistd.h>
#include <zmq.h>

#include <cmath>
#include <cstring>
#include <random>

#include "graph/stats.hpp"
#include "graph/wire_format.hpp"
#include "io/openpose_json.hpp"
#include "support/mocap_process.hpp"
#include "support/network.hpp"

namespace mocap::test {
namespace {

using namespace std::chrono_literals;
namespace wire = graph::wire;

const char* const kFolder = "../shared/data/eval/openpose_json/json";
constexpr int kFrames = 60;

// `python3 ARGS...` with stderr into a file; waits are bounded, the child is killed at the end.
class Python : public ChildProcess {
 public:
  Python(const TempDir& dir, std::vector<std::string> args)
      : ChildProcess(MOCAP_PYTHON3, std::move(args), "/dev/null", dir.file("python.err"),
                     environment()) {}
};

bool python_has_zmq() {
  return std::system((std::string(MOCAP_PYTHON3) + " -c 'import zmq' 2>/dev/null").c_str()) == 0;
}

// A raw ZeroMQ socket for the test's own side.
class Socket {
 public:
  // What is sent stays queued up to `linger_ms` for a peer that is slow to bind (a loaded
  // machine, a sanitizer build: 2 s lost the garbage under ASan).
  Socket(int type, const std::string& endpoint, int linger_ms = 20000) {
    socket_ = zmq_socket(context_, type);
    const int linger = linger_ms, timeout = 30000;
    zmq_setsockopt(socket_, ZMQ_LINGER, &linger, sizeof linger);
    zmq_setsockopt(socket_, ZMQ_RCVTIMEO, &timeout, sizeof timeout);
    if (type == ZMQ_SUB) zmq_setsockopt(socket_, ZMQ_SUBSCRIBE, "", 0);
    if (zmq_connect(socket_, endpoint.c_str()) != 0) throw std::runtime_error("connect failed");
  }
  ~Socket() {
    zmq_close(socket_);
    zmq_ctx_term(context_);
  }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;

  void send(const std::vector<std::string>& parts) {
    for (std::size_t i = 0; i < parts.size(); ++i) {
      zmq_send(socket_, parts[i].data(), parts[i].size(), i + 1 < parts.size() ? ZMQ_SNDMORE : 0);
    }
  }
  // One whole message decoded, or nullopt after the receive timeout.
  std::optional<graph::Packet> receive() {
    struct Part {
      zmq_msg_t message;
      Part() { zmq_msg_init(&message); }
      ~Part() { zmq_msg_close(&message); }
      Part(const Part&) = delete;
      Part& operator=(const Part&) = delete;
    };
    std::vector<wire::Frame> frames;
    bool more = true;
    while (more) {
      auto part = std::make_shared<Part>();
      if (zmq_msg_recv(&part->message, socket_, 0) < 0) return std::nullopt;
      more = zmq_msg_more(&part->message) != 0;
      frames.push_back({static_cast<const std::byte*>(zmq_msg_data(&part->message)),
                        zmq_msg_size(&part->message), part});
    }
    return wire::decode(frames).packet;
  }

 private:
  void* context_ = zmq_ctx_new();
  void* socket_ = nullptr;
};

std::string bytes(const wire::Frame& f) {
  return std::string(reinterpret_cast<const char*>(f.data), f.size);
}

// A valid People2D (COCO-17, two people) as strings, for the test to spoil.
std::vector<std::string> valid_people() {
  auto m = std::make_shared<People2D>();
  m->header = {"garbage", 0, 1, 0};
  m->layout = LayoutId::coco17;
  m->people.resize(2);
  for (Person2D& p : m->people) p.joints.resize(17, Keypoint2D{1, 2, 0.5f});
  std::vector<std::string> parts;
  for (const wire::Frame& f : wire::encode(graph::Packet::of<People2D>(m), 0))
    parts.push_back(bytes(f));
  return parts;
}

// Seven messages the node must refuse, each for another reason.
std::vector<std::vector<std::string>> garbage() {
  std::vector<std::vector<std::string>> bad;
  std::mt19937 random(7);
  std::string noise(200, '\0');
  for (char& c : noise) c = static_cast<char>(random());
  bad.push_back({noise});  // random bytes
  const auto valid = valid_people();
  bad.push_back({valid[0].substr(0, 20)});                                       // truncated header
  bad.push_back({valid[0], valid[1], valid[2].substr(0, valid[2].size() - 5)});  // short keypoints
  auto version = valid;
  version[0][4] = 2;  // wire format version 2: before messages named their camera
  bad.push_back(version);
  auto oversized = valid;
  const std::uint32_t people = 5000;  // beyond the 4096 limit
  std::memcpy(oversized[1].data() + 4, &people, 4);
  bad.push_back(oversized);
  auto joints = valid;
  const std::uint16_t layout = 1;  // BODY_25 with 17 keypoints per person
  std::memcpy(joints[1].data(), &layout, 2);
  bad.push_back(joints);
  auto stats = std::make_shared<graph::GraphStats>();
  stats->graph = "g";
  std::vector<std::string> wrong_type;
  for (const wire::Frame& f : wire::encode(graph::Packet::of<graph::GraphStats>(stats), 0))
    wrong_type.push_back(bytes(f));
  bad.push_back(wrong_type);
  return bad;
}

bool same(float a, float b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

class RemoteKeypointsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!python_has_zmq())
      GTEST_SKIP() << MOCAP_PYTHON3 << " cannot import zmq (apt-get install python3-zmq)";
    if (!std::filesystem::is_directory(kFolder)) GTEST_SKIP() << kFolder << " is absent";
  }
  TempDir dir_;
};

TEST_F(RemoteKeypointsTest, KeypointsFromPythonArriveAsSentAndGarbageIsCounted) {
  const std::string in = "tcp://127.0.0.1:" + std::to_string(free_tcp_port());
  const std::string out = "tcp://127.0.0.1:" + std::to_string(free_tcp_port());
  const std::string graph = dir_.file("g.yaml");
  write_file(graph,
             "graph: remote_test\n"
             "nodes:\n"
             "  remote: { type: source.remote_keypoints, params: { endpoint: \"" +
                 in +
                 "\", timeout_ms: 60000 } }\n"
                 "  pub: { type: sink.publish, params: { endpoint: \"" +
                 out +
                 "\", wait_for_subscriber: true } }\n"
                 "edges:\n"
                 "  - [remote.out, pub.in]\n");
  Mocap run(dir_, "run", {"run", graph});
  Socket subscriber(ZMQ_SUB, out);
  {
    Socket sender(ZMQ_PUSH, in);
    for (const auto& message : garbage()) sender.send(message);
  }
  ASSERT_TRUE(run.wait_for_log("rejected message (7)", 30s)) << run.err();
  {
    // Beyond ZeroMQ's 16 MiB limit of the node: that sender is disconnected (not counted), and
    // the node goes on.
    Socket huge(ZMQ_PUSH, in, 2000);
    huge.send({std::string(17u << 20, 'x')});
  }
  EXPECT_TRUE(run.wait_for_log("rejected message 1: .* from 127\\.0\\.0\\.1 on " + in, 1s))
      << run.err();

  Python client(dir_,
                {"tools/remote/send_keypoints.py", kFolder, "--endpoint", in, "--layout", "BODY_25",
                 "--limit", std::to_string(kFrames), "--stream", "py", "--camera", "side_left"});
  ASSERT_EQ(client.wait(60s), 0) << client.err();

  io::OpenPoseOptions options;
  options.body25 = io::Body25Choice::body25;
  const io::OpenPoseSequence expected = io::read_openpose_folder(kFolder, options);
  ASSERT_GE(expected.frames.size(), static_cast<std::size_t>(kFrames));
  int received = 0;
  std::size_t people = 0;
  for (;;) {
    const auto packet = subscriber.receive();
    ASSERT_TRUE(packet) << "no message for 30 s after " << received << "\n" << run.err();
    if (packet->is_end_of_stream()) break;
    ASSERT_EQ(packet->type, People2D::kTypeName);
    const auto& m = static_cast<const People2D&>(*packet->message);
    const std::size_t i = static_cast<std::size_t>(received);
    ASSERT_LT(i, static_cast<std::size_t>(kFrames));
    const People2D& want = expected.frames[i];
    EXPECT_EQ(m.header.stream, "py");
    EXPECT_EQ(m.camera, "side_left");  // wire format 3: the sender names its camera
    EXPECT_EQ(m.header.seq, i);
    EXPECT_EQ(m.header.frame, want.header.frame);
    EXPECT_GT(m.header.capture_ns, 0);
    EXPECT_EQ(m.layout, LayoutId::body25);
    ASSERT_EQ(m.people.size(), want.people.size()) << "frame " << i;
    for (std::size_t p = 0; p < m.people.size(); ++p) {
      const Person2D &a = m.people[p], &b = want.people[p];
      EXPECT_EQ(a.id, b.id);
      EXPECT_EQ(a.box.x, b.box.x);
      EXPECT_EQ(a.box.y, b.box.y);
      EXPECT_EQ(a.box.width, b.box.width);
      EXPECT_EQ(a.box.height, b.box.height);
      ASSERT_EQ(a.joints.size(), b.joints.size());
      for (std::size_t j = 0; j < a.joints.size(); ++j) {
        EXPECT_TRUE(same(a.joints[j].x, b.joints[j].x) && same(a.joints[j].y, b.joints[j].y) &&
                    same(a.joints[j].confidence, b.joints[j].confidence))
            << "frame " << i << " person " << p << " joint " << j << ": " << a.joints[j].x << ","
            << a.joints[j].y << "," << a.joints[j].confidence << " vs " << b.joints[j].x << ","
            << b.joints[j].y << "," << b.joints[j].confidence;
      }
    }
    people += m.people.size();
    ++received;
  }
  EXPECT_EQ(received, kFrames);
  EXPECT_GT(people, 0u);
  // The graph ends with the Python client's EndOfStream; the statistics show the 7 drops and the
  // node's status names the last rejection.
  ASSERT_EQ(run.wait(30s), 0) << run.err();
  const std::string log = run.err();
  EXPECT_NE(log.find(std::to_string(kFrames) + " People2D received, 7 rejected"), std::string::npos)
      << log;
  EXPECT_TRUE(std::regex_search(log, std::regex("remote +source.remote_keypoints +[0-9]+ +" +
                                                std::to_string(kFrames) + " +7 ")))
      << log;
  EXPECT_NE(log.find("remote: 7 message(s) rejected; last: GraphStats where People2D"),
            std::string::npos)
      << log;
}

// bind: false: the node connects to a sender that binds (send_keypoints.py --bind), which may
// start first; PUSH keeps the frames until the node is there.
TEST_F(RemoteKeypointsTest, TheNodeCanConnectToASenderThatBinds) {
  const std::string endpoint = "tcp://127.0.0.1:" + std::to_string(free_tcp_port());
  Python client(dir_, {"tools/remote/send_keypoints.py", kFolder, "--endpoint", endpoint, "--bind",
                       "--limit", "20"});
  std::this_thread::sleep_for(500ms);
  const std::string graph = dir_.file("g.yaml");
  write_file(graph,
             "nodes:\n"
             "  remote: { type: source.remote_keypoints, params: { endpoint: \"" +
                 endpoint +
                 "\", bind: false, timeout_ms: 30000 } }\n"
                 "  collect: { type: test.collect, params: { path: \"" +
                 dir_.file("got.txt") +
                 "\" } }\n"
                 "edges:\n"
                 "  - [remote.out, collect.in]\n");
  Mocap run(dir_, "run", {"run", graph});
  ASSERT_EQ(run.wait(60s), 0) << run.err();
  ASSERT_EQ(client.wait(30s), 0) << client.err();
  EXPECT_EQ(read_lines(dir_.file("got.txt")).size(), 20u) << run.err();
  EXPECT_NE(run.err().find("20 People2D received, 0 rejected"), std::string::npos) << run.err();
}

TEST_F(RemoteKeypointsTest, SilenceEndsTheStreamAfterTheTimeout) {
  const std::string graph = dir_.file("g.yaml");
  write_file(graph,
             "nodes:\n"
             "  remote: { type: source.remote_keypoints, params: { endpoint: \"ipc://" +
                 dir_.file("in") +
                 "\", timeout_ms: 300 } }\n"
                 "  pass: { type: flow.pass_through }\n"
                 "edges:\n"
                 "  - [remote.out, pass.in]\n");
  Mocap run(dir_, "run", {"run", graph});
  ASSERT_EQ(run.wait(20s), 0) << run.err();
  EXPECT_NE(run.err().find("no message for 300 ms"), std::string::npos) << run.err();
}

TEST(RemoteKeypointsGraph, Validates) {
  TempDir dir;
  Mocap validate(dir, "validate", {"graph", "validate", "graphs/remote_keypoints.yaml"});
  ASSERT_EQ(validate.wait(30s), 0) << validate.err() << validate.out();
}

}  // namespace
}  // namespace mocap::test
