#pragma once
// The viewer's HTTP + WebSocket server (Boost.Beast, kept inside web_server.cpp): serves the page,
// three.js from the npm cache under /three/, and text frames over the WebSocket /ws to every
// connected browser. One server thread does all network work; broadcast() only hands a message
// over, so the caller (a graph node) never waits for a browser. Each browser has a bounded queue:
// when it is full the oldest waiting frame is dropped and counted (a slow browser skips frames).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

namespace mocap::web {

struct ServerOptions {
  std::string host = "127.0.0.1";   // loopback by default; "0.0.0.0" serves every interface
  int port = 0;                     // 0: the kernel picks a free port (see WebServer::port())
  std::size_t queue_frames = 4;     // frames waiting per browser before the oldest is dropped
  std::filesystem::path three_dir;  // the npm package `three` (node_modules/three); see below
  // Sent first to every browser that connects (e.g. the skeleton's joint names and bones).
  std::string greeting;
  // Text messages from browsers (playback controls), called on the server thread.
  std::function<void(const std::string&)> on_message;
};

struct ServerStats {
  std::uint64_t clients = 0;        // connected now
  std::uint64_t clients_total = 0;  // ever connected
  std::uint64_t broadcasts = 0;     // messages given to broadcast()
  std::uint64_t sent = 0;           // messages written to a browser
  std::uint64_t dropped = 0;        // messages dropped from a full browser queue
  std::uint64_t http_requests = 0;
};

class WebServer {
 public:
  // Binds and starts serving; throws std::runtime_error naming host and port when it cannot.
  explicit WebServer(ServerOptions options);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  int port() const;
  std::string url() const;  // http://HOST:PORT/
  // Queues `text` for every connected browser and remembers it for browsers that connect later.
  // Thread-safe, never blocks on the network.
  void broadcast(std::string text);
  ServerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Where tools/setup.sh installs three.js:
// ${MOCAP_NPM_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/mocap/npm}/node_modules/three
std::filesystem::path default_three_dir();

}  // namespace mocap::web
