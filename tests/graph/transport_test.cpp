// ZeroMQ edges with real sockets over inproc://, ipc:// and tcp://127.0.0.1: order, images,
// backpressure, garbage on the socket, and a whole graph with transport edges in one process.

#include <gtest/gtest.h>

#include <thread>
#include <zmq.hpp>

#include "graph/runtime.hpp"
#include "graph/transport.hpp"
#include "graph_test_util.hpp"

namespace mocap::graph {
namespace {

using testing::TempDir;

std::string endpoint(const std::string& kind, const TempDir& dir) {
  if (kind == "inproc") return "inproc://transport-test";
  if (kind == "ipc") return "ipc://" + dir.file("edge");
  return "tcp://127.0.0.1:" + std::to_string(testing::free_tcp_port());
}

class Transport : public ::testing::TestWithParam<std::string> {};

Packet numbered(std::uint64_t seq) {
  auto m = std::make_shared<People2D>();
  m->header = {"s", seq, static_cast<std::int64_t>(seq) * 10, static_cast<std::int64_t>(seq)};
  m->people.push_back(Person2D{static_cast<int>(seq), {{1, 2, 3}}, {}});
  return Packet::of<People2D>(m);
}

std::optional<wire::Decoded> receive_one(Receiver& receiver, std::string* rejected = nullptr) {
  for (int attempt = 0; attempt < 100; ++attempt) {  // up to 10 s
    Receiver::Result r = receiver.receive(std::chrono::milliseconds(100));
    if (r.message) return std::move(r.message);
    if (!r.rejected.empty()) {
      if (rejected) *rejected = r.rejected;
      return std::nullopt;
    }
  }
  ADD_FAILURE() << "nothing received in 10 s";
  return std::nullopt;
}

TEST_P(Transport, MessagesArriveInOrderWithImagesIntact) {
  TempDir dir;
  TransportContext context;
  const std::string where = endpoint(GetParam(), dir);
  Receiver receiver(context, where);
  Sender sender(context, where, Sender::Pattern::edge);
  constexpr int kMessages = 1000;
  std::thread producer([&] {
    for (int i = 0; i < kMessages; ++i)
      ASSERT_TRUE(sender.send(numbered(static_cast<std::uint64_t>(i))));
    auto frame = std::make_shared<VideoFrame>();
    frame->image = ImageBuffer(1920, 1080, PixelFormat::rgb8);
    frame->image.pixels_for_writing()[1920 * 3 * 1079 + 5] = std::byte{0xAB};
    ASSERT_TRUE(sender.send(Packet::of<VideoFrame>(frame)));
    ASSERT_TRUE(sender.send(Packet::end_of_stream()));
  });
  for (int i = 0; i < kMessages; ++i) {
    const auto got = receive_one(receiver);
    ASSERT_TRUE(got);
    ASSERT_EQ(got->packet.header().seq, static_cast<std::uint64_t>(i));
    EXPECT_GT(got->send_ns, 0);
  }
  const auto frame = receive_one(receiver);
  ASSERT_TRUE(frame);
  const auto& image = static_cast<const VideoFrame&>(*frame->packet.message).image;
  EXPECT_EQ(image.width(), 1920);
  EXPECT_EQ(image.data()[1920 * 3 * 1079 + 5], std::byte{0xAB});
  EXPECT_TRUE(receive_one(receiver)->packet.is_end_of_stream());
  producer.join();
}

TEST_P(Transport, GarbageOnTheSocketIsRejectedAndValidMessagesStillPass) {
  TempDir dir;
  TransportContext context;
  const std::string where = endpoint(GetParam(), dir);
  Receiver receiver(context, where);
  // A foreign program that speaks ZeroMQ but not our format.
  void* raw = zmq_socket(context.native_handle(), ZMQ_DEALER);
  const int linger = 0;
  zmq_setsockopt(raw, ZMQ_LINGER, &linger, sizeof linger);
  ASSERT_EQ(zmq_connect(raw, where.c_str()), 0);
  auto send = [&](const std::vector<std::string>& parts) {
    for (std::size_t i = 0; i < parts.size(); ++i) {
      zmq_send(raw, parts[i].data(), parts[i].size(), i + 1 < parts.size() ? ZMQ_SNDMORE : 0);
    }
  };
  auto to_strings = [](const std::vector<wire::Frame>& frames) {
    std::vector<std::string> parts;
    for (const auto& f : frames) parts.emplace_back(reinterpret_cast<const char*>(f.data), f.size);
    return parts;
  };
  std::vector<std::string> valid = to_strings(wire::encode(numbered(5), 0));
  std::vector<std::string> wrong_version = valid;
  wrong_version[0][4] = 9;
  std::vector<std::string> truncated = valid;
  truncated[2].resize(truncated[2].size() - 3);
  std::string random_bytes(1000, '\0');
  for (std::size_t i = 0; i < random_bytes.size(); ++i)
    random_bytes[i] = static_cast<char>(i * 131 + 7);

  const std::vector<std::vector<std::string>> garbage = {
      {"hello"}, {random_bytes}, wrong_version, truncated, std::vector<std::string>(20, valid[0]),
      {""}};
  for (const auto& message : garbage) send(message);
  send(valid);
  for (std::size_t i = 0; i < garbage.size(); ++i) {
    std::string why;
    EXPECT_FALSE(receive_one(receiver, &why)) << "garbage " << i << " was accepted";
    EXPECT_FALSE(why.empty()) << "garbage " << i;
  }
  const auto good = receive_one(receiver);
  ASSERT_TRUE(good);
  EXPECT_EQ(good->packet.header().seq, 5u);
  zmq_close(raw);
}

TEST_P(Transport, GraphWithTransportEdgesInOneProcessMatchesInProcessEdges) {
  TempDir dir;
  const std::string where = endpoint(GetParam(), dir);
  auto graph_text = [&](const std::string& transport, const std::string& out) {
    return "nodes:\n"
           "  src: { type: test.counter, params: { count: 500, people: 2 } }\n"
           "  cam: { type: test.frames, params: { count: 5, width: 320, height: 240 } }\n"
           "  pass: { type: flow.pass_through }\n"
           "  sink: { type: test.collect, params: { path: " +
           dir.file(out) +
           " } }\n"
           "  images: { type: test.collect, params: { path: " +
           dir.file(out + ".images") +
           " } }\n"
           "edges:\n"
           "  - [src.out, pass.in" +
           (transport.empty() ? "" : ", { transport: \"" + transport + "\" }") +
           "]\n"
           "  - [pass.out, sink.in]\n"
           "  - [cam.frames, images.in" +
           (transport.empty() ? "" : ", { transport: \"" + transport + "-img\" }") + "]\n";
  };
  const std::string image_endpoint =
      GetParam() == "tcp" ? "tcp://127.0.0.1:" + std::to_string(testing::free_tcp_port())
                          : where + "-img";
  std::string with_transport = graph_text(where, "zmq.txt");
  // tcp endpoints need distinct ports rather than a suffix.
  const auto suffixed = with_transport.find(where + "-img");
  with_transport.replace(suffixed, where.size() + 4, image_endpoint);
  for (const auto& [text, out] : {std::pair{graph_text("", "local.txt"), "local.txt"},
                                  std::pair{with_transport, "zmq.txt"}}) {
    Runtime runtime(resolve(parse_graph_text(text, "t.yaml")));
    const RunResult result = runtime.run();
    ASSERT_TRUE(result.ok) << result.error;
    (void)out;
  }
  EXPECT_EQ(testing::read_lines(dir.file("local.txt")).size(), 500u);
  EXPECT_EQ(testing::read_file(dir.file("local.txt")), testing::read_file(dir.file("zmq.txt")));
  EXPECT_EQ(testing::read_lines(dir.file("local.txt.images")).size(), 5u);
  EXPECT_EQ(testing::read_file(dir.file("local.txt.images")),
            testing::read_file(dir.file("zmq.txt.images")));
}

INSTANTIATE_TEST_SUITE_P(AllTransports, Transport, ::testing::Values("inproc", "ipc", "tcp"));

}  // namespace
}  // namespace mocap::graph
