// source.remote_keypoints: 2D keypoints from another process over ZeroMQ, in the wire format
// (docs/wire-format.md), so a detector in any language or on another machine feeds the graph.
//
// The socket is a PULL socket (the sender uses PUSH). PUSH/PULL, not PUB/SUB, because every frame
// matters to the tracker downstream: PUSH holds messages while nobody is connected and makes the
// sender wait when the graph falls behind (the `queue` high-water mark), where PUB would drop
// them, including the first ones sent before a subscription arrived. Several detectors may
// connect to one bound node; their messages are interleaved fairly.
//
// Every message is checked (wire_format.cpp, plus: People2D or EndOfStream only, the joint count
// of the layout). A bad one is counted as this node's drop, named with its sender in the node's
// status line and on stderr, and skipped: the graph goes on. EndOfStream ends the stream, and
// so does `timeout_ms` of silence when it is set.

#include <chrono>
#include <iostream>

#include "graph/keys.hpp"
#include "graph/registry.hpp"
#include "graph/transport.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class RemoteKeypoints : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("2D keypoints (People2D) from another process over ZeroMQ PULL, in the wire format");
    c.output<People2D>("out", "the keypoints as sent (ids as sent, -1 when untracked)");
    c.required_param<std::string>(
        "endpoint",
        "where to bind (or connect), e.g. tcp://127.0.0.1:5570 or ipc:///tmp/mocap-keypoints "
        "(beyond loopback: allow_network and CURVE keys, docs/security.md)");
    c.param<bool>("bind", true,
                  "bind the endpoint (senders connect, any number); false: connect to a sender "
                  "that binds");
    c.network_socket("endpoint", "bind");
    c.param<double>("timeout_ms", 0.0,
                    "end of stream after this long without a message (0: wait until EndOfStream "
                    "or the graph stops)",
                    {0, 3.6e8});
    c.param<std::int64_t>("queue", 100, "messages held before senders wait", {1, 1e6});
    c.param<std::int64_t>("log_rejections", 10,
                          "rejected messages described on stderr (then every 100th)", {0, 1e9});
  }

  void open(Context& ctx) override {
    SocketOptions options;
    options.high_water_mark = ctx.param<int>("queue");
    // A People2D at the format's limits (4096 people x 256 joints) is 12.6 MB; anything larger
    // is refused by ZeroMQ before it is allocated (the sender's connection is dropped).
    options.max_message_bytes = std::int64_t{16} << 20;
    options.curve = node_curve_keys(ctx, ctx.param<bool>("bind"));
    endpoint_ = ctx.param<std::string>("endpoint");
    receiver_ = std::make_unique<Receiver>(
        context_, endpoint_, options,
        ctx.param<bool>("bind") ? Receiver::Pattern::pull_bind : Receiver::Pattern::pull_connect);
    const double timeout_ms = ctx.param<double>("timeout_ms");
    timeout_ = std::chrono::milliseconds(static_cast<std::int64_t>(timeout_ms));
    log_rejections_ = ctx.param<std::uint64_t>("log_rejections");
    last_message_ = Clock::now();
    std::cerr << ctx.node_name() << ": receiving keypoints on " << endpoint_ << "\n";
  }

  void process(Context& ctx) override {
    // Bounded, so that a stop request is seen within a tenth of a second.
    Receiver::Result result = receiver_->receive(std::chrono::milliseconds(100));
    if (!result.message && result.rejected.empty()) {
      if (timeout_.count() > 0 && Clock::now() - last_message_ >= timeout_) {
        std::cerr << ctx.node_name() << ": no message for " << timeout_.count() << " ms on "
                  << endpoint_ << "; ending the stream\n";
        ctx.report_status("ended: no message for " + std::to_string(timeout_.count()) + " ms");
        ctx.finish();
      }
      return;
    }
    last_message_ = Clock::now();
    if (!result.message) return reject(ctx, result.rejected, result.peer);
    const Packet& packet = result.message->packet;
    if (packet.is_end_of_stream()) {
      std::cerr << ctx.node_name() << ": end of stream from " << sender(result.peer) << "\n";
      ctx.finish();
      return;
    }
    if (packet.type != People2D::kTypeName) {
      return reject(ctx, std::string(packet.type) + " where People2D was expected", result.peer);
    }
    auto people = std::static_pointer_cast<const People2D>(packet.message);
    const std::size_t joints = layout(people->layout).keypoints.size();
    for (const Person2D& person : people->people) {
      if (person.joints.size() != joints) {
        return reject(ctx,
                      "People2D: layout " + std::string(layout(people->layout).name) + " has " +
                          std::to_string(joints) + " keypoints, the message " +
                          std::to_string(person.joints.size()),
                      result.peer);
      }
    }
    if (people->header.capture_ns == 0) {  // the sender does not know: arrival is the best guess
      auto stamped = std::make_shared<People2D>(*people);
      stamped->header.capture_ns = realtime_ns();
      people = std::move(stamped);
    }
    ++received_;
    ctx.send("out", std::move(people));
  }

  void close(Context& ctx) override {
    std::cerr << ctx.node_name() << ": " << received_ << " People2D received, " << rejected_
              << " rejected" << (last_rejection_.empty() ? "" : " (last: " + last_rejection_ + ")")
              << "\n";
  }

 private:
  using Clock = std::chrono::steady_clock;

  std::string sender(const std::string& peer) const {
    return peer.empty() ? "a sender on " + endpoint_ : peer + " on " + endpoint_;
  }

  void reject(Context& ctx, const std::string& why, const std::string& peer) {
    ++rejected_;
    ctx.count_drop();
    last_rejection_ = why + ", from " + sender(peer);
    ctx.report_status(std::to_string(rejected_) + " message(s) rejected; last: " + last_rejection_);
    if (rejected_ <= log_rejections_ || rejected_ % 100 == 0) {
      std::cerr << ctx.node_name() << ": rejected message " << rejected_ << ": " << last_rejection_
                << "\n";
    }
  }

  TransportContext context_;  // declared first: it must outlive the socket
  std::unique_ptr<Receiver> receiver_;
  std::string endpoint_;
  std::chrono::milliseconds timeout_{0};
  Clock::time_point last_message_;
  std::uint64_t received_ = 0, rejected_ = 0, log_rejections_ = 10;
  std::string last_rejection_;
};

MOCAP_REGISTER_NODE("source.remote_keypoints", RemoteKeypoints)

}  // namespace mocap::nodes
