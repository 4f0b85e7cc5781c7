#pragma once
// The node API. A node type is a class with a static contract() and the lifecycle
// open / process / close; MOCAP_REGISTER_NODE (registry.hpp) makes it available by name. A real
// one, components/nodes/recon/smooth_1euro.cpp, shortened:
//
//   class Smooth1EuroNode : public Node {
//    public:
//     static void contract(Contract& c) {
//       c.doc("Smooths each person's 3D joints with the 1-Euro filter (online)");
//       c.input<People3D>("in");
//       c.output<People3D>("out");
//       c.param<double>("beta", 0.4, "cutoff slope", {0.0, 100.0});
//     }
//     void open(Context& ctx) override { params_.beta = ctx.param<double>("beta"); }
//     void process(Context& ctx) override {
//       People3D out = ctx.input<People3D>("in");
//       ...  // recon::OneEuroFilterVec3 per person and joint (the library does the work)
//       ctx.send("out", std::move(out));
//     }
//    private:
//     recon::OneEuroParams params_;
//   };
//   MOCAP_REGISTER_NODE("recon.smooth_1euro", Smooth1EuroNode)
//
// Threading: each node runs on its own thread, so a node's members need no locks.
// docs/node-authoring.md says more, including how to test a node alone (graph/harness.hpp).

#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

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

  // --- inputs. process() is called once per arriving message, for exactly one input port; for a
  // node whose contract joins inputs (Contract::join), once per set of the joined inputs, each
  // present or missing (has). A repeated input's edges are read by index (0..input_count - 1).
  // The port of the single message being processed; for a set, the first joined input present.
  virtual std::string_view input_port() const = 0;  // empty in sources
  bool has(std::string_view port, std::size_t index = 0) const {
    return find_input(port, index) != nullptr;
  }
  // Edges wired to `port`: 0 or 1 for a plain input, N for a repeated one.
  virtual std::size_t input_count(std::string_view port) const = 0;
  // True while process() handles a set of joined inputs.
  virtual bool in_set() const = 0;
  template <class T>
  const T& input(std::string_view port, std::size_t index = 0) const {
    return *input_ptr<T>(port, index);
  }
  template <class T>
  std::shared_ptr<const T> input_ptr(std::string_view port, std::size_t index = 0) const;
  const Header& header() const {
    if (const Header* h = input_header()) return *h;
    throw std::logic_error("node '" + node_name() + "': no input message in this call");
  }

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
  // Stream `index` of a repeated output (Contract::outputs).
  template <class T>
  void send(std::string_view port, std::size_t index, T message) {
    if (message.header == Header{}) {
      if (const Header* inherited = input_header()) message.header = *inherited;
    }
    send_packet(port, index, Packet::of<T>(std::make_shared<const T>(std::move(message))));
  }
  // Sends the current input on unchanged, without a copy (pass-through, flow control).
  void forward(std::string_view output, std::string_view input) {
    send_packet(output, current(input));
  }
  // True when every node that output `port` (stream `index` of a repeated one) feeds in this
  // process has nothing queued and is not processing: sending now starts work at once. A consumer
  // in another process cannot be seen and counts as idle. For flow control (flow.set_limiter).
  virtual bool output_idle(std::string_view port, std::size_t index = 0) const = 0;
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

  // The primitives the helpers above are made of.
  virtual const Header* input_header() const = 0;  // of the message being processed, or null
  // The message of `port` (edge `index` of a repeated input) in this call, or null.
  virtual const Packet* find_input(std::string_view port, std::size_t index = 0) const = 0;
  // As find_input, but throws (a bug in the node) when the port holds no message in this call.
  const Packet& current(std::string_view port, std::size_t index = 0) const;
  void send_packet(std::string_view port, Packet packet) {
    send_packet(port, 0, std::move(packet));
  }
  // `index`: the stream of a repeated output; 0 for a plain one.
  virtual void send_packet(std::string_view port, std::size_t index, Packet packet) = 0;
  virtual const ParamValue& param_value(std::string_view name) const = 0;
};

class Node {
 public:
  virtual ~Node() = default;
  virtual void open(Context&) {}
  // Sources (no inputs) are called in a loop until they call ctx.finish() or the graph stops;
  // other nodes once per input message, or once per set of their joined inputs.
  virtual void process(Context& ctx) = 0;
  // Called after the last message (also when the graph is stopped): flush files here.
  virtual void close(Context&) {}
};

template <class T>
struct is_vector : std::false_type {};
template <class T>
struct is_vector<std::vector<T>> : std::true_type {};

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
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    if (const auto* v = std::get_if<std::vector<std::string>>(&value)) return *v;
  } else if constexpr (std::is_same_v<T, std::vector<double>> ||
                       std::is_same_v<T, std::vector<float>>) {
    if (const auto* v = std::get_if<std::vector<double>>(&value)) return T(v->begin(), v->end());
  } else if constexpr (is_vector<T>::value) {
    if (const auto* v = std::get_if<std::vector<std::int64_t>>(&value)) {
      return T(v->begin(), v->end());
    }
  } else {
    if (const auto* v = std::get_if<std::string>(&value)) return T(*v);
  }
  throw std::logic_error("node '" + node_name() + "': parameter '" + std::string(name) +
                         "' read with the wrong type");
}

inline const Packet& Context::current(std::string_view port, std::size_t index) const {
  if (const Packet* packet = find_input(port, index)) return *packet;
  throw std::logic_error("node '" + node_name() + "': input '" + std::string(port) +
                         (index ? ":" + std::to_string(index) : std::string()) +
                         "' holds no message in this call (check ctx.has first)");
}

template <class T>
std::shared_ptr<const T> Context::input_ptr(std::string_view port, std::size_t index) const {
  const Packet& packet = current(port, index);
  if (packet.type != T::kTypeName) {
    throw std::logic_error("node '" + node_name() + "': input '" + std::string(port) + "' holds " +
                           std::string(packet.type) + ", read as " + std::string(T::kTypeName));
  }
  return std::static_pointer_cast<const T>(packet.message);
}

}  // namespace mocap::graph
