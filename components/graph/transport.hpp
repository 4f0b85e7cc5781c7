#pragma once
// ZeroMQ edges, behind a small interface so that no other file includes zmq.hpp. A Sender
// connects a DEALER socket (or binds a PUB/XPUB socket for streams others subscribe to); a Receiver
// binds a DEALER socket (DEALER pairs, so
// the consumer can acknowledge the end of stream). Messages are encoded in the wire format
// (wire_format.hpp); large frames (images) are handed to ZeroMQ without a copy on both sides.
// Shutdown never hangs: every socket has a bounded linger, sends wait in short slices and ask
// whether to give up, receives poll with a timeout.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "graph/wire_format.hpp"

namespace mocap::graph {

// One per process; outlives every socket made from it. When a socket of it is a CURVE server,
// the context also runs the guard: a thread answering ZeroMQ's authentication requests (ZAP, on
// inproc://zeromq.zap.01) from the sockets' allow-lists, and watching the sockets' handshakes, so
// that every refused connection is logged on stderr (rate-limited) and counted.
class TransportContext {
 public:
  TransportContext();
  ~TransportContext();
  TransportContext(const TransportContext&) = delete;
  TransportContext& operator=(const TransportContext&) = delete;

  struct Impl;
  Impl& impl() { return *impl_; }
  void* native_handle();  // the zmq context (void*), for tests that speak raw ZeroMQ
  // Connections refused so far: a client key not on the allow-list, a failed CURVE handshake (no
  // keys, a wrong server key), or, on a connecting socket, a server that refused this one.
  std::uint64_t refused_connections() const;

 private:
  std::unique_ptr<Impl> impl_;
};

// ZeroMQ CURVE keys of one socket, Z85 text (40 characters each; docs/security.md). The end that
// binds is the CURVE server: its own secret key, and the public keys of the clients it lets in
// (no others). The end that connects is a client: its own secret key and the server's public key.
struct CurveKeys {
  std::string secret_key;                    // this socket's own secret key; empty: no CURVE
  std::string server_public_key;             // connecting sockets: the server's public key
  std::vector<std::string> allowed_clients;  // binding sockets: the clients' public keys

  bool enabled() const { return !secret_key.empty(); }
};

struct SocketOptions {
  int high_water_mark = 16;  // messages queued per socket before the sender waits (or drops)
  int linger_ms = 1000;      // how long unsent messages may delay closing
  std::int64_t max_message_bytes = std::int64_t{512} << 20;  // larger frames drop the connection
  CurveKeys curve;                                           // empty: plain ZeroMQ
};

// True when this libzmq was built with CURVE (Debian's is, through libsodium).
bool curve_available();
struct CurveKeyPair {
  std::string public_key, secret_key;  // Z85, 40 characters each
};
// A fresh key pair from libsodium's random source. Throws std::runtime_error without CURVE.
CurveKeyPair generate_curve_key_pair();
// The public key that belongs to a secret key. Throws std::runtime_error when `secret_key` is not
// a Z85 key.
std::string curve_public_key(const std::string& secret_key);
// 40 characters of the Z85 alphabet: what a CURVE key looks like as text.
bool looks_like_z85_key(std::string_view text);

class Sender {
 public:
  enum class Pattern {
    edge,           // DEALER, connects: one consumer, backpressure, end-of-stream acknowledged
    publish_bind,   // any number of subscribers, never waits (drops when they lag)
    xpublish_bind,  // like publish_bind, and wait_for_subscriber() works
  };
  // Throws std::runtime_error naming the endpoint when it cannot connect or bind.
  Sender(TransportContext& context, const std::string& endpoint, Pattern pattern,
         SocketOptions options = {});
  ~Sender();
  Sender(const Sender&) = delete;
  Sender& operator=(const Sender&) = delete;

  // Sends one message. While the peer's queue is full it waits in 50 ms slices, calling
  // `give_up` between them; returns false (message not sent) when it does.
  bool send(const Packet& packet, const std::function<bool()>& give_up = {});
  // Pattern::edge: true once the consumer has confirmed an end of stream. Closing before that can
  // lose the last messages (libzmq drops what a full receiver has not yet queued when the peer
  // disconnects), so producers wait for it, bounded, before they exit.
  bool poll_acknowledgement();
  // xpublish_bind: waits until at least one subscriber has subscribed.
  bool wait_for_subscriber(std::chrono::milliseconds timeout);
  const std::string& endpoint() const { return endpoint_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string endpoint_;
  bool acknowledged_ = false;
};

class Receiver {
 public:
  enum class Pattern {
    edge,          // DEALER, binds: the consumer of a graph edge (acknowledges end of stream)
    pull_bind,     // PULL, binds: any number of PUSH producers connect (other programs)
    pull_connect,  // PULL, connects to one PUSH producer that binds
  };
  Receiver(TransportContext& context, const std::string& endpoint, SocketOptions options = {},
           Pattern pattern = Pattern::edge);
  ~Receiver();
  Receiver(const Receiver&) = delete;
  Receiver& operator=(const Receiver&) = delete;

  struct Result {
    std::optional<wire::Decoded> message;  // a valid message
    std::string rejected;                  // or why a malformed one was dropped
    std::string peer;  // the sender's address where ZeroMQ knows it (tcp: its IP), else ""
  };
  // Waits up to `timeout`; both fields empty when nothing arrived.
  Result receive(std::chrono::milliseconds timeout);
  // Tells the producer that its end of stream arrived (see Sender::poll_acknowledgement).
  void acknowledge_end();
  const std::string& endpoint() const { return endpoint_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string endpoint_;
};

std::int64_t realtime_ns();  // CLOCK_REALTIME, the clock of capture timestamps

}  // namespace mocap::graph
