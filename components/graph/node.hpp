#pragma once
// The node API. A node type is a class with a static contract() and the lifecycle
// open / process / close; MOCAP_REGISTER_NODE (registry.hpp) makes it available by name:
//
//   class Smoother : public Node {
//    public:
//     static void contract(Contract& c) {
//       c.input<People3D>("in");
//       c.output<People3D>("out");
//       c.param<double>("beta", 0.4, "1-Euro cutoff slope", {0.0, 10.0});
//     }
//     void open(Context& ctx) override { filter_.set_beta(ctx.param<double>("beta")); }
//     void process(Context& ctx) override { ctx.send("out",
//     filter_.apply(ctx.input<People3D>("in"))); }
//    private:
//     recon::OneEuro filter_;
//   };
//   MOCAP_REGISTER_NODE("recon.smooth_1euro", Smoother);
//
// Threading: each node runs on its own thread, so a node's members need no locks.

#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

#include "graph/contract.hpp"
#include "graph/packet.hpp"
#include "graph/stats.hpp"

namespace mocap::graph {

class Context {
 public:
  virtual ~Context() = default;

  virtual const std::string& node_name() const = 0;

  // Parameters were checked against the contract before open(), so this only throws on a bug
  // (a name or type the contract does not declare).
  template <class T>
  T param(std::string_view name) const;

  // --- inputs: process() is called once per arriving message, for exactly one input port.
  virtual std::string_view input_port() const = 0;  // empty in sources
  bool has(std::string_view port) const { return input_port() == port; }
  template <class T>
  const T& input(std::string_view port) const {
    return *input_ptr<T>(port);
  }
  template <class T>
  std::shared_ptr<const T> input_ptr(std::string_view port) const;
  const Header& header() const { return current(input_port()).header(); }

  // --- outputs. A message whose header is empty (no stream, no capture time) inherits the
  // header of the input being processed, so stages after a source rarely touch headers.
  template <class T>
  void send(std::string_view port, T message) {
    if (message.header == Header{}) {
      if (const Header* inherited = input_header()) message.header = *inherited;
    }
    send(port, std::make_shared<const T>(std::move(message)));
  }
  template <class T>
  void send(std::string_view port, std::shared_ptr<const T> message) {
    send_packet(port, Packet::of<T>(std::move(message)));
  }
  // Sends the current input on unchanged, without a copy (pass-through, flow control).
  void forward(std::string_view output, std::string_view input) {
    send_packet(output, current(input));
  }
  // Counts a message this node chose to discard (flow limiters); shown with the edge drops.
  virtual void count_drop() = 0;
  // Replaces the node's status line in the graph's statistics (GraphStats, the table printed at
  // the end): events a user should see while the graph runs, e.g. a camera lost and reconnected
  // or messages rejected. Nodes still print to stderr as before; this does not.
  virtual void report_status(std::string text) { static_cast<void>(text); }

  // --- sources
  virtual void finish() = 0;  // no more messages: EndOfStream follows on every output
  virtual bool stop_requested() const = 0;
  // Sleeps, waking early when the graph stops; returns false when it should stop.
  virtual bool sleep_for(std::chrono::nanoseconds duration) = 0;

  virtual GraphStats stats() const = 0;

  // The primitives the helpers above are made of (and what a test harness implements).
  virtual const Header* input_header() const = 0;  // of the message being processed, or null
  virtual const Packet& current(std::string_view port) const = 0;
  virtual void send_packet(std::string_view port, Packet packet) = 0;
  virtual const ParamValue& param_value(std::string_view name) const = 0;
};

class Node {
 public:
  virtual ~Node() = default;
  virtual void open(Context&) {}
  // Sources (no inputs) are called in a loop until they call ctx.finish() or the graph stops;
  // other nodes once per input message.
  virtual void process(Context& ctx) = 0;
  // Called after the last message (also when the graph is stopped): flush files here.
  virtual void close(Context&) {}
};

template <class T>
T Context::param(std::string_view name) const {
  const ParamValue& value = param_value(name);
  if constexpr (std::is_same_v<T, bool>) {
    if (const auto* v = std::get_if<bool>(&value)) return *v;
  } else if constexpr (std::is_integral_v<T>) {
    if (const auto* v = std::get_if<std::int64_t>(&value)) return static_cast<T>(*v);
  } else if constexpr (std::is_floating_point_v<T>) {
    if (const auto* v = std::get_if<double>(&value)) return static_cast<T>(*v);
    if (const auto* v = std::get_if<std::int64_t>(&value)) return static_cast<T>(*v);
  } else {
    if (const auto* v = std::get_if<std::string>(&value)) return T(*v);
  }
  throw std::logic_error("node '" + node_name() + "': parameter '" + std::string(name) +
                         "' read with the wrong type");
}

template <class T>
std::shared_ptr<const T> Context::input_ptr(std::string_view port) const {
  const Packet& packet = current(port);
  if (packet.type != T::kTypeName) {
    throw std::logic_error("node '" + node_name() + "': input '" + std::string(port) + "' holds " +
                           std::string(packet.type) + ", read as " + std::string(T::kTypeName));
  }
  return std::static_pointer_cast<const T>(packet.message);
}

}  // namespace mocap::graph
