// The viewer's server over real loopback sockets: the page and three.js over HTTP, nothing outside
// the three package, garbage requests, the WebSocket greeting and last frame for a new browser,
// and a browser that never reads: its frames are dropped and counted, broadcast never waits.

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <thread>

#include "support/files.hpp"
#include "web/web_server.hpp"

namespace mocap::web {
namespace {

using namespace std::chrono_literals;

// A loopback TCP client with a receive timeout; `receive_buffer` > 0 shrinks the kernel buffer.
class Client {
 public:
  explicit Client(int port, int receive_buffer = 0) : fd_(socket(AF_INET, SOCK_STREAM, 0)) {
    if (receive_buffer > 0)
      setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
    timeval timeout{2, 0};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    connected_ = connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0;
  }
  ~Client() { close(fd_); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  bool connected() const { return connected_; }
  void send_text(const std::string& text) const {
    ASSERT_EQ(::send(fd_, text.data(), text.size(), MSG_NOSIGNAL),
              static_cast<ssize_t>(text.size()));
  }
  // Everything until the server closes (or the timeout).
  std::string read_all() const {
    std::string out;
    char buffer[65536];
    for (ssize_t n; (n = recv(fd_, buffer, sizeof buffer, 0)) > 0;)
      out.append(buffer, static_cast<std::size_t>(n));
    return out;
  }
  // Exactly `n` bytes, or fewer on timeout or close.
  std::string read_exactly(std::size_t n) const {
    std::string out;
    char buffer[4096];
    while (out.size() < n) {
      const ssize_t got = recv(fd_, buffer, std::min(sizeof buffer, n - out.size()), 0);
      if (got <= 0) break;
      out.append(buffer, static_cast<std::size_t>(got));
    }
    return out;
  }
  std::string read_until(const std::string& end) const {
    std::string out;
    char c;
    while (out.find(end) == std::string::npos && recv(fd_, &c, 1, 0) == 1) out.push_back(c);
    return out;
  }
  // One unmasked server-to-browser WebSocket frame's payload (RFC 6455 5.2), for the test only.
  std::optional<std::string> read_ws_frame() const {
    const std::string head = read_exactly(2);
    if (head.size() != 2) return std::nullopt;
    std::size_t length = static_cast<unsigned char>(head[1]) & 0x7f;
    if (length >= 126) {
      const std::string ext = read_exactly(length == 126 ? 2 : 8);
      length = 0;
      for (const char c : ext) length = (length << 8) | static_cast<unsigned char>(c);
    }
    std::string payload = read_exactly(length);
    if (payload.size() != length) return std::nullopt;
    return payload;
  }

 private:
  int fd_;
  bool connected_ = false;
};

std::string get(int port, const std::string& target, const std::string& method = "GET") {
  Client client(port);
  client.send_text(method + " " + target +
                   " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
  return client.read_all();
}

const std::string kHandshake =
    "GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
    "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";

template <class Predicate>
bool eventually(Predicate done, std::chrono::milliseconds timeout = 5s) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(10ms);
  }
  return true;
}

class WebServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::create_directories(dir_.path() / "three" / "build");
    test::write_file((dir_.path() / "three" / "build" / "three.module.js").string(),
                     "export const REVISION = 'test';\n");
    test::write_file((dir_.path() / "three" / "package.json").string(), "{}");
    test::write_file(dir_.file("secret.txt"), "secret");
  }
  ServerOptions options() const {
    ServerOptions o;
    o.three_dir = dir_.path() / "three";
    o.greeting = "{\"type\":\"hello\"}";
    return o;
  }
  test::TempDir dir_;
};

TEST_F(WebServerTest, ServesThePageAndThreeOnAFreeLoopbackPort) {
  WebServer server(options());
  ASSERT_GT(server.port(), 0);
  EXPECT_EQ(server.url(), "http://127.0.0.1:" + std::to_string(server.port()) + "/");
  const std::string page = get(server.port(), "/");
  EXPECT_NE(page.find("HTTP/1.1 200 OK"), std::string::npos) << page.substr(0, 200);
  EXPECT_NE(page.find("text/html"), std::string::npos);
  EXPECT_NE(page.find("<canvas id=\"canvas3d\">"), std::string::npos);
  EXPECT_NE(page.find("id=\"people\""), std::string::npos);
  const std::string script = get(server.port(), "/viewer.js?v=1");
  EXPECT_NE(script.find("text/javascript"), std::string::npos);
  EXPECT_NE(script.find("import * as THREE from \"three\""), std::string::npos);
  const std::string three = get(server.port(), "/three/build/three.module.js");
  EXPECT_NE(three.find("200 OK"), std::string::npos);
  EXPECT_NE(three.find("REVISION = 'test'"), std::string::npos);
  const std::string head = get(server.port(), "/", "HEAD");
  EXPECT_NE(head.find("200 OK"), std::string::npos);
  EXPECT_EQ(head.find("<canvas"), std::string::npos);
}

TEST_F(WebServerTest, NothingOutsideThePageAndThreesBuildAndExamples) {
  WebServer server(options());
  for (const char* target :
       {"/three/package.json", "/three/../secret.txt", "/three/build/../../secret.txt",
        "/three/build/%2e%2e/%2e%2e/secret.txt", "/secret.txt", "/three/build/absent.js", "/ws",
        "//etc/passwd"}) {
    const std::string response = get(server.port(), target);
    EXPECT_NE(response.find("404"), std::string::npos) << target << ": " << response.substr(0, 80);
    EXPECT_EQ(response.find("secret\n"), std::string::npos);
  }
  EXPECT_NE(get(server.port(), "/", "POST").find("405"), std::string::npos);
}

TEST_F(WebServerTest, GarbageRequestsCloseTheirConnectionOnlyAndTheServerGoesOn) {
  WebServer server(options());
  for (const std::string& garbage :
       {std::string("\x00\x01\x02garbage\r\n\r\n", 15),
        std::string("GET / HTTP/1.1\r\nContent-Length: -5\r\n\r\n"), std::string(100000, 'A'),
        std::string("GET /ws HTTP/1.1\r\nConnection: Upgrade\r\nUpgrade: websocket\r\n\r\n")}) {
    Client client(server.port());
    ASSERT_TRUE(client.connected());
    const auto start = std::chrono::steady_clock::now();
    client.send_text(garbage.substr(0, 65536));
    client.read_all();  // the server answers or closes at once; it must not wait for more
    EXPECT_LT(std::chrono::steady_clock::now() - start, 1s) << garbage.substr(0, 20);
  }
  EXPECT_NE(get(server.port(), "/").find("200 OK"), std::string::npos);
}

TEST_F(WebServerTest, ABrowserGetsTheGreetingThenTheLastFrameThenNewFrames) {
  std::string received;
  ServerOptions o = options();
  std::atomic<int> messages{0};
  o.on_message = [&](const std::string&) { ++messages; };
  WebServer server(std::move(o));
  server.broadcast("{\"frame\":1}");
  server.broadcast("{\"frame\":2}");
  Client client(server.port());
  client.send_text(kHandshake);
  const std::string response = client.read_until("\r\n\r\n");
  ASSERT_NE(response.find("101"), std::string::npos) << response;
  EXPECT_EQ(client.read_ws_frame().value_or("none"), "{\"type\":\"hello\"}");
  EXPECT_EQ(client.read_ws_frame().value_or("none"), "{\"frame\":2}");
  ASSERT_TRUE(eventually([&] { return server.stats().clients == 1; }));
  server.broadcast(std::string(70000, 'x'));  // a 64-bit length
  EXPECT_EQ(client.read_ws_frame().value_or("none").size(), 70000u);
  // A masked text frame from the browser ("play") reaches on_message.
  const std::string mask = "abcd", text = "play";
  std::string frame = "\x81";
  frame.push_back(static_cast<char>(0x80 | text.size()));
  frame += mask;
  for (std::size_t i = 0; i < text.size(); ++i) frame.push_back(text[i] ^ mask[i % 4]);
  client.send_text(frame);
  EXPECT_TRUE(eventually([&] { return messages == 1; }));
}

TEST_F(WebServerTest, ABrowserThatNeverReadsLosesFramesAndNeverBlocksTheSender) {
  ServerOptions o = options();
  o.queue_frames = 4;
  WebServer server(std::move(o));
  Client slow(server.port(), 4096);
  slow.send_text(kHandshake);
  ASSERT_NE(slow.read_until("\r\n\r\n").find("101"), std::string::npos);
  ASSERT_TRUE(eventually([&] { return server.stats().clients == 1; }));
  const std::string frame(64 * 1024, 'x');
  constexpr int kFrames = 2000;  // 128 MB if nothing were dropped
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kFrames; ++i) server.broadcast(frame);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 2.0) << "broadcast waited for the browser";
  ASSERT_TRUE(eventually([&] {
    const ServerStats s = server.stats();
    // Every frame is written or dropped, but the queue's 4 and the one being written.
    return s.sent + s.dropped >= kFrames - 5;
  }));
  const ServerStats s = server.stats();
  EXPECT_EQ(s.broadcasts, static_cast<std::uint64_t>(kFrames));
  EXPECT_GT(s.dropped, static_cast<std::uint64_t>(kFrames) / 2);
  EXPECT_LT(s.sent, static_cast<std::uint64_t>(kFrames) / 2);
  // Another browser still gets the newest frame at once.
  Client fast(server.port());
  fast.send_text(kHandshake);
  ASSERT_NE(fast.read_until("\r\n\r\n").find("101"), std::string::npos);
  EXPECT_EQ(fast.read_ws_frame().value_or("none"), "{\"type\":\"hello\"}");
  EXPECT_EQ(fast.read_ws_frame().value_or("none").size(), frame.size());
}

TEST(WebServer, AnAddressInUseOrUnknownHostIsAClearError) {
  WebServer first(ServerOptions{});
  ServerOptions same;
  same.port = first.port();
  try {
    WebServer second(same);
    // SO_REUSEADDR does not allow two listeners on Linux; reaching here is a failure.
    ADD_FAILURE() << "second server on the same port";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot listen on 127.0.0.1:" + std::to_string(same.port)),
              std::string::npos)
        << e.what();
  }
  ServerOptions elsewhere;
  elsewhere.host = "192.0.2.1";  // TEST-NET-1: not an address of this machine
  EXPECT_THROW(WebServer{elsewhere}, std::runtime_error);
}

}  // namespace
}  // namespace mocap::web
