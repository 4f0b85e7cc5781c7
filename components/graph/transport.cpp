#include "graph/transport.hpp"

#include <time.h>

#include <thread>
#include <vector>
#include <zmq.hpp>

namespace mocap::graph {

std::int64_t realtime_ns() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return std::int64_t{now.tv_sec} * 1'000'000'000 + now.tv_nsec;
}

struct TransportContext::Impl {
  zmq::context_t context{1};
};

TransportContext::TransportContext() : impl_(std::make_unique<Impl>()) {}
TransportContext::~TransportContext() = default;
void* TransportContext::native_handle() { return impl_->context.handle(); }

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

void configure(zmq::socket_t& socket, const SocketOptions& options) {
  socket.set(zmq::sockopt::linger, options.linger_ms);
  socket.set(zmq::sockopt::sndhwm, options.high_water_mark);
  socket.set(zmq::sockopt::rcvhwm, options.high_water_mark);
  socket.set(zmq::sockopt::maxmsgsize, options.max_message_bytes);
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
  configure(impl_->socket, options);
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
  configure(impl_->socket, options);
  const bool connect = pattern == Pattern::pull_connect;
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
