// sink.publish: publishes every message it receives on a ZeroMQ PUB socket in the wire format
// (docs/wire-format.md), for any number of subscribers in any language; sends EndOfStream last.
// Subscribers that cannot keep up lose messages (PUB never holds the graph back).

#include "graph/keys.hpp"
#include "graph/registry.hpp"
#include "graph/transport.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class Publish : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Publishes messages on a ZeroMQ PUB socket in the mocap wire format");
    c.input_any("in");
    c.required_param<std::string>(
        "endpoint",
        "where to bind, e.g. tcp://127.0.0.1:5560 or ipc:///tmp/mocap-out (beyond loopback: "
        "allow_network and CURVE keys, docs/security.md)");
    c.network_socket("endpoint");
    c.param<bool>("wait_for_subscriber", false, "hold the first message until a subscriber joined");
    c.param<double>("wait_timeout_ms", 10000.0, "how long to wait for that subscriber", {0, 3.6e6});
    c.param<std::int64_t>("queue", 1000, "messages queued per slow subscriber before dropping",
                          {1, 1e6});
  }
  void open(Context& ctx) override {
    const bool wait = ctx.param<bool>("wait_for_subscriber");
    SocketOptions options;
    options.high_water_mark = ctx.param<int>("queue");
    options.curve = node_curve_keys(ctx, true);
    sender_ = std::make_unique<Sender>(
        context_, ctx.param<std::string>("endpoint"),
        wait ? Sender::Pattern::xpublish_bind : Sender::Pattern::publish_bind, options);
    const auto timeout =
        std::chrono::milliseconds(static_cast<std::int64_t>(ctx.param<double>("wait_timeout_ms")));
    if (wait && !sender_->wait_for_subscriber(timeout)) {
      throw std::runtime_error("no subscriber on " + sender_->endpoint() + " within " +
                               std::to_string(timeout.count()) + " ms");
    }
  }
  void process(Context& ctx) override {
    if (!sender_->send(ctx.current("in"))) ctx.count_drop();
  }
  void close(Context&) override {
    if (sender_) sender_->send(Packet::end_of_stream());
  }

 private:
  TransportContext context_;  // declared first: it must outlive the socket
  std::unique_ptr<Sender> sender_;
};

MOCAP_REGISTER_NODE("sink.publish", Publish)

}  // namespace mocap::nodes
