#include "graph/transport.hpp"

#include <time.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <iostream>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>
#include <zmq.hpp>

namespace mocap::graph {

std::int64_t realtime_ns() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return std::int64_t{now.tv_sec} * 1'000'000'000 + now.tv_nsec;
}

namespace {

constexpr std::string_view kZ85Alphabet =
    "0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ.-:+=^!/*?&<>()[]{}@%$#";

std::string z85_of(const unsigned char* key) {
  char text[41] = {};
  zmq_z85_encode(text, key, 32);
  return text;
}

// Rate-limited logging of refusals: the first few of each socket, then every 100th (a refused
// client reconnects every few hundred milliseconds).
bool worth_logging(std::uint64_t count) { return count <= 5 || count % 100 == 0; }

}  // namespace

bool curve_available() { return zmq_has("curve") == 1; }

bool looks_like_z85_key(std::string_view text) {
  return text.size() == 40 && std::all_of(text.begin(), text.end(), [](char c) {
           return kZ85Alphabet.find(c) != std::string_view::npos;
         });
}

CurveKeyPair generate_curve_key_pair() {
  if (!curve_available()) {
    throw std::runtime_error("this libzmq has no CURVE security (built without libsodium)");
  }
  char public_key[41] = {}, secret_key[41] = {};
  if (zmq_curve_keypair(public_key, secret_key) != 0) {
    throw std::runtime_error(std::string("cannot make a CURVE key pair: ") +
                             zmq_strerror(zmq_errno()));
  }
  return {public_key, secret_key};
}

std::string curve_public_key(const std::string& secret_key) {
  if (!looks_like_z85_key(secret_key)) throw std::runtime_error("not a Z85 CURVE key");
  char public_key[41] = {};
  if (zmq_curve_public(public_key, secret_key.c_str()) != 0) {
    throw std::runtime_error(std::string("not a CURVE secret key: ") + zmq_strerror(zmq_errno()));
  }
  return public_key;
}

// The guard of a context (see transport.hpp). Sockets register here from any thread; the guard
// thread owns the ZAP socket and the monitor sockets.
struct TransportContext::Impl {
  struct Watched {
    std::string endpoint;           // the socket's endpoint, for messages
    bool server = false;            // binds (CURVE server) or connects (client)
    std::set<std::string> allowed;  // servers: the clients' public keys, Z85
    std::uint64_t refused = 0;
    std::map<std::string, std::uint64_t> reasons;  // refusals by message, for rate-limiting
  };

  zmq::context_t context{1};
  std::mutex mutex;
  std::map<std::string, Watched> watched;     // by ZAP domain (servers) or monitor endpoint
  std::vector<std::string> pending_monitors;  // monitor endpoints the guard has to connect
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> refused{0};
  int next_id = 0;
  std::thread guard;  // last member: stopped and joined first

  ~Impl() {
    stop = true;
    if (guard.joinable()) guard.join();
  }

  // Registers a CURVE socket before it binds or connects: returns its ZAP domain (servers),
  // after arranging that its handshakes are watched.
  std::string watch(zmq::socket_t& socket, const std::string& endpoint, bool server,
                    const std::vector<std::string>& allowed) {
    std::lock_guard lock(mutex);
    const std::string id = "mocap-" + std::to_string(next_id++);
    if (!guard.joinable()) {
      // The ZAP handler must be bound before the first handshake: bind it here, then hand the
      // socket to the guard thread (thread start is a full memory barrier).
      zmq::socket_t zap(context, zmq::socket_type::rep);
      zap.set(zmq::sockopt::linger, 0);
      zap.bind("inproc://zeromq.zap.01");
      guard = std::thread([this, zap = std::move(zap)]() mutable { run(zap); });
    }
    const std::string monitor = "inproc://mocap-monitor-" + id;
    const int events = ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL | ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL |
                       ZMQ_EVENT_HANDSHAKE_FAILED_AUTH;
    if (zmq_socket_monitor(socket.handle(), monitor.c_str(), events) != 0) {
      throw std::runtime_error("cannot watch the socket of " + endpoint + ": " +
                               zmq_strerror(zmq_errno()));
    }
    Watched entry{endpoint, server, {allowed.begin(), allowed.end()}, 0, {}};
    watched[id] = entry;
    pending_monitors.push_back(id);
    return id;
  }

  // Logs the first few refusals of each kind (each unknown client key and address is a kind of
  // its own), then every 100th.
  void refuse(Watched& socket, const std::string& why) {
    ++refused;
    ++socket.refused;
    constexpr std::size_t kMaxKinds = 256;  // beyond that, counted together
    const std::string kind = socket.reasons.size() < kMaxKinds || socket.reasons.count(why)
                                 ? why
                                 : std::string("(other)");
    if (worth_logging(++socket.reasons[kind])) {
      std::cerr << (socket.server ? "refused a connection on " : "connection to ")
                << socket.endpoint << (socket.server ? ": " : " refused: ") << why << " ("
                << socket.refused << " so far)\n";
    }
  }

  // ZAP (rfc.zeromq.org/spec/27): version, request id, domain, address, routing id, mechanism,
  // credentials (CURVE: the client's 32-byte public key). Answers 200 for a listed key, else 400.
  void answer(zmq::socket_t& zap) {
    std::vector<zmq::message_t> request;
    bool more = true;
    while (more && request.size() < 16) {
      zmq::message_t part;
      if (!zap.recv(part)) return;
      more = part.more();
      request.push_back(std::move(part));
    }
    while (more) {  // a malformed request: read the rest, answer nothing sensible
      zmq::message_t part;
      if (!zap.recv(part)) return;
      more = part.more();
    }
    std::string status = "400", text = "not allowed";
    if (request.size() >= 7 && request[0].to_string_view() == "1.0") {
      const std::string domain(request[2].to_string_view());
      const std::string address(request[3].to_string_view());
      const std::string mechanism(request[5].to_string_view());
      std::lock_guard lock(mutex);
      const auto it = watched.find(domain);
      const std::string key = mechanism == "CURVE" && request[6].size() == 32
                                  ? z85_of(request[6].data<unsigned char>())
                                  : "";
      if (it != watched.end() && !key.empty() && it->second.allowed.count(key)) {
        status = "200";
        text = "OK";
      } else if (it != watched.end()) {
        refuse(it->second, "client key " + (key.empty() ? mechanism : key) + " from " +
                               (address.empty() ? "an unknown address" : address) +
                               " is not on the allow-list");
      }
    }
    const std::string version = "1.0";
    const std::string id = request.size() > 1 ? std::string(request[1].to_string_view()) : "";
    zap.send(zmq::buffer(version), zmq::send_flags::sndmore);
    zap.send(zmq::buffer(id), zmq::send_flags::sndmore);
    zap.send(zmq::buffer(status), zmq::send_flags::sndmore);
    zap.send(zmq::buffer(text), zmq::send_flags::sndmore);
    zap.send(zmq::str_buffer(""), zmq::send_flags::sndmore);
    zap.send(zmq::str_buffer(""), zmq::send_flags::none);
  }

  // A monitor event: frame 1 is u16 event + u32 value, frame 2 the endpoint.
  void event(zmq::socket_t& monitor, const std::string& id) {
    zmq::message_t head, address;
    if (!monitor.recv(head)) return;
    if (head.more() && !monitor.recv(address)) return;
    if (head.size() < 6) return;
    std::uint16_t code = 0;
    std::uint32_t value = 0;
    std::memcpy(&code, head.data(), 2);
    std::memcpy(&value, static_cast<const char*>(head.data()) + 2, 4);
    std::lock_guard lock(mutex);
    auto it = watched.find(id);
    if (it == watched.end()) return;
    Watched& socket = it->second;
    if (code == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) {
      if (!socket.server) refuse(socket, "the server does not accept this client's key");
      return;  // servers: logged with the key by answer()
    }
    std::string why = "CURVE handshake failed";
    if (value == ZMQ_PROTOCOL_ERROR_ZMTP_MECHANISM_MISMATCH) {
      why += socket.server ? " (the client has no CURVE keys)" : " (the server does not use CURVE)";
    } else if (value == ZMQ_PROTOCOL_ERROR_ZMTP_CRYPTOGRAPHIC) {
      why += socket.server ? " (the client has the wrong server key)" : " (wrong keys)";
    } else if (code == ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL && socket.server) {
      why += " (the client left during it: it has no CURVE keys, or not for this server)";
    }
    refuse(socket, why);
  }

  void run(zmq::socket_t& zap) {
    std::vector<std::pair<zmq::socket_t, std::string>> monitors;
    while (!stop) {
      {
        std::lock_guard lock(mutex);
        for (const std::string& id : pending_monitors) {
          zmq::socket_t monitor(context, zmq::socket_type::pair);
          monitor.set(zmq::sockopt::linger, 0);
          monitor.connect("inproc://mocap-monitor-" + id);
          monitors.emplace_back(std::move(monitor), id);
        }
        pending_monitors.clear();
      }
      std::vector<zmq::pollitem_t> items{{zap.handle(), 0, ZMQ_POLLIN, 0}};
      for (auto& [monitor, id] : monitors) items.push_back({monitor.handle(), 0, ZMQ_POLLIN, 0});
      try {
        if (zmq::poll(items, std::chrono::milliseconds(20)) == 0) continue;
        if (items[0].revents & ZMQ_POLLIN) answer(zap);
        for (std::size_t i = 1; i < items.size(); ++i) {
          if (items[i].revents & ZMQ_POLLIN) event(monitors[i - 1].first, monitors[i - 1].second);
        }
      } catch (const zmq::error_t& e) {
        // Only when the context goes away, which waits for this thread: nothing left to guard.
        std::cerr << "transport guard: " << e.what() << "\n";
        return;
      }
    }
  }
};

TransportContext::TransportContext() : impl_(std::make_unique<Impl>()) {}
TransportContext::~TransportContext() = default;
void* TransportContext::native_handle() { return impl_->context.handle(); }
std::uint64_t TransportContext::refused_connections() const { return impl_->refused; }

namespace {

// Frames at least this large go to ZeroMQ by reference: copying them would cost more than the
// bookkeeping. Smaller ones are copied into the message, which is cheaper than a callback.
constexpr std::size_t kZeroCopyBytes = 4096;

void release_owner(void* /*data*/, void* hint) {
  // Runs on a ZeroMQ I/O thread once the frame is sent; drops our reference to the bytes.
  std::unique_ptr<std::shared_ptr<const void>> owner(
      static_cast<std::shared_ptr<const void>*>(hint));
}

zmq::message_t to_message(const wire::Frame& frame) {
  if (frame.size < kZeroCopyBytes || !frame.owner) return zmq::message_t(frame.data, frame.size);
  auto owner = std::make_unique<std::shared_ptr<const void>>(frame.owner);
  zmq::message_t message(const_cast<std::byte*>(frame.data), frame.size, &release_owner,
                         owner.get());
  [[maybe_unused]] auto* released = owner.release();  // now owned by the ZeroMQ message
  return message;
}

// Every option is set right after the socket is made, before it binds or connects: CURVE keys
// only apply to connections made after they are set.
void configure(zmq::socket_t& socket, const SocketOptions& options, TransportContext& context,
               const std::string& endpoint, bool binds) {
  socket.set(zmq::sockopt::linger, options.linger_ms);
  socket.set(zmq::sockopt::sndhwm, options.high_water_mark);
  socket.set(zmq::sockopt::rcvhwm, options.high_water_mark);
  socket.set(zmq::sockopt::maxmsgsize, options.max_message_bytes);
  const CurveKeys& curve = options.curve;
  if (!curve.enabled()) return;
  if (!curve_available()) {
    throw std::runtime_error(
        endpoint +
        ": CURVE keys are set, but this libzmq has no CURVE security "
        "(zmq_has(\"curve\") is false: a libzmq built with libsodium is needed)");
  }
  if (!looks_like_z85_key(curve.secret_key)) {
    throw std::runtime_error(endpoint + ": the CURVE secret key is not a Z85 key");
  }
  try {
    if (binds) {
      const std::string domain =
          context.impl().watch(socket, endpoint, true, curve.allowed_clients);
      socket.set(zmq::sockopt::zap_domain, domain);
      socket.set(zmq::sockopt::curve_server, true);
      socket.set(zmq::sockopt::curve_secretkey, curve.secret_key);
    } else {
      if (!looks_like_z85_key(curve.server_public_key)) {
        throw std::runtime_error(endpoint + ": the CURVE server key is not a Z85 key");
      }
      context.impl().watch(socket, endpoint, false, {});
      socket.set(zmq::sockopt::curve_serverkey, curve.server_public_key);
      socket.set(zmq::sockopt::curve_publickey, curve_public_key(curve.secret_key));
      socket.set(zmq::sockopt::curve_secretkey, curve.secret_key);
    }
  } catch (const zmq::error_t& e) {
    throw std::runtime_error(endpoint + ": cannot set the CURVE keys: " + e.what());
  }
}

// ZeroMQ's "Peer-Address" message property: the sender's IP for tcp, empty where unknown.
std::string peer_address(zmq::message_t& message) {
  const char* address = zmq_msg_gets(message.handle(), "Peer-Address");
  return address ? address : "";
}

std::runtime_error endpoint_error(const std::string& what, const std::string& endpoint,
                                  const zmq::error_t& e) {
  return std::runtime_error("cannot " + what + " " + endpoint + ": " + e.what());
}

}  // namespace

struct Sender::Impl {
  zmq::socket_t socket;
  Pattern pattern;
};

Sender::Sender(TransportContext& context, const std::string& endpoint, Pattern pattern,
               SocketOptions options)
    : endpoint_(endpoint) {
  const auto type = pattern == Pattern::edge           ? zmq::socket_type::dealer
                    : pattern == Pattern::publish_bind ? zmq::socket_type::pub
                                                       : zmq::socket_type::xpub;
  impl_ = std::make_unique<Impl>(Impl{zmq::socket_t(context.impl().context, type), pattern});
  configure(impl_->socket, options, context, endpoint, pattern != Pattern::edge);
  impl_->socket.set(zmq::sockopt::sndtimeo, 50);
  try {
    if (pattern == Pattern::edge) {
      impl_->socket.connect(endpoint);
    } else {
      impl_->socket.bind(endpoint);
    }
  } catch (const zmq::error_t& e) {
    throw endpoint_error(pattern == Pattern::edge ? "connect to" : "bind", endpoint, e);
  }
}

Sender::~Sender() = default;  // zmq::socket_t closes with the linger set above

bool Sender::send(const Packet& packet, const std::function<bool()>& give_up) {
  const std::vector<wire::Frame> frames = wire::encode(packet, realtime_ns());
  std::vector<zmq::message_t> parts;
  parts.reserve(frames.size());
  for (const wire::Frame& frame : frames) parts.push_back(to_message(frame));
  // ZeroMQ applies the high-water mark to the first part only: once it is accepted the rest of
  // the message follows without waiting.
  while (!impl_->socket.send(parts[0],
                             parts.size() > 1 ? zmq::send_flags::sndmore : zmq::send_flags::none)) {
    if (impl_->pattern != Pattern::edge) return false;  // PUB never waits; nothing to do
    if (give_up && give_up()) return false;
  }
  for (std::size_t i = 1; i < parts.size(); ++i) {
    impl_->socket.send(parts[i],
                       i + 1 < parts.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
  }
  return true;
}

bool Sender::poll_acknowledgement() {
  if (impl_->pattern != Pattern::edge) return true;
  zmq::message_t reply;
  while (impl_->socket.recv(reply, zmq::recv_flags::dontwait)) {
    if (reply.to_string_view() == wire::kEndAcknowledgement) acknowledged_ = true;
  }
  return acknowledged_;
}

bool Sender::wait_for_subscriber(std::chrono::milliseconds timeout) {
  if (impl_->pattern != Pattern::xpublish_bind) return true;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  impl_->socket.set(zmq::sockopt::rcvtimeo, 50);
  while (std::chrono::steady_clock::now() < deadline) {
    zmq::message_t subscription;
    // XPUB delivers subscriptions as messages whose first byte is 1.
    if (impl_->socket.recv(subscription) && subscription.size() > 0 &&
        subscription.data<unsigned char>()[0] == 1) {
      return true;
    }
  }
  return false;
}

struct Receiver::Impl {
  zmq::socket_t socket;
};

Receiver::Receiver(TransportContext& context, const std::string& endpoint, SocketOptions options,
                   Pattern pattern)
    : endpoint_(endpoint) {
  const auto type = pattern == Pattern::edge ? zmq::socket_type::dealer : zmq::socket_type::pull;
  impl_ = std::make_unique<Impl>(Impl{zmq::socket_t(context.impl().context, type)});
  const bool connect = pattern == Pattern::pull_connect;
  configure(impl_->socket, options, context, endpoint, !connect);
  try {
    if (connect) {
      impl_->socket.connect(endpoint);
    } else {
      impl_->socket.bind(endpoint);
    }
  } catch (const zmq::error_t& e) {
    throw endpoint_error(connect ? "connect to" : "bind", endpoint, e);
  }
}

Receiver::~Receiver() = default;

void Receiver::acknowledge_end() {
  // Never waits: a producer that is gone (or restarting) simply does not get it.
  zmq::message_t ack(wire::kEndAcknowledgement.data(), wire::kEndAcknowledgement.size());
  [[maybe_unused]] auto sent = impl_->socket.send(ack, zmq::send_flags::dontwait);
}

Receiver::Result Receiver::receive(std::chrono::milliseconds timeout) {
  zmq::pollitem_t item{impl_->socket.handle(), 0, ZMQ_POLLIN, 0};
  if (zmq::poll(&item, 1, timeout) == 0) return {};
  // Read every part of the message, but keep no more than the format allows.
  std::vector<wire::Frame> frames;
  std::size_t parts = 0;
  bool more = true;
  std::string peer;
  while (more) {
    auto part = std::make_shared<zmq::message_t>();
    if (!impl_->socket.recv(*part)) break;
    more = part->more();
    if (parts == 0) peer = peer_address(*part);
    if (++parts <= wire::kMaxFrames + 1) {
      frames.push_back(
          wire::Frame{static_cast<const std::byte*>(part->data()), part->size(), part});
    }
  }
  if (parts > wire::kMaxFrames + 1) {
    return {std::nullopt, "too many frames (" + std::to_string(parts) + ")", peer};
  }
  try {
    return {wire::decode(frames), {}, peer};
  } catch (const wire::WireError& e) {
    return {std::nullopt, e.what(), peer};
  }
}

}  // namespace mocap::graph
