#pragma once
// What a node type declares about itself, statically: input and output ports with their message
// types and parameters with type, default, range and a one-line doc. The framework checks graphs
// against contracts before any node runs, and `mocap graph inspect` prints them.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "graph/params.hpp"

namespace mocap::graph {

struct PortSpec {
  std::string name;
  std::string type;       // message type name; empty: any type
  std::string same_as;    // outputs: carries the type of this input (pass-through nodes)
  bool optional = false;  // inputs: may stay unconnected
  std::string doc;
  // Inputs: a repeated input takes min_count..max_count edges, wired to name:0, name:1, ...
  // Outputs: a repeated output has one stream per edge of the repeated input `per_edge_of`
  // (name:i goes with that input's edge i), each wired to any number of edges as name:i.
  bool repeated = false;
  std::size_t min_count = 1, max_count = 1;
  std::string per_edge_of{};

  bool any() const { return type.empty() && same_as.empty(); }
};

enum class PortFlag { required, optional };

// What the inputs of a set are matched by (graph/synchronizer.hpp).
enum class SyncKey { frame, capture_time };

// What becomes of a message that arrives after its set went on without it (graph/synchronizer.hpp).
enum class LateMessages {
  pass,  // passed on alone, as a set of its own (a sink that draws or records every message)
  drop,  // counted and dropped: a node that makes one output per set (never two for one frame)
};

// A node's joined inputs: process() is called once per set of messages that belong together (the
// same frame number, or capture times within a tolerance) instead of once per message. The
// contract gives the defaults of the parameters that tune it (sync_by, sync_bound,
// sync_tolerance_ms, sync_wait_ms), which a graph can override like any other.
struct JoinSpec {
  std::vector<std::string> ports;  // input names; a repeated input joins all its edges
  SyncKey key = SyncKey::frame;
  std::int64_t bound = 64;  // messages held per port at most
  double tolerance_ms = 0;  // capture_time: how far apart the messages of one set may be
  double wait_ms = 0;       // a partial set goes on after this wall-clock wait; 0: never
  LateMessages late = LateMessages::pass;
};

class Contract {
 public:
  void doc(std::string text) { doc_ = std::move(text); }

  template <class T>
  void input(std::string name, std::string doc = {}, PortFlag flag = PortFlag::required) {
    add_input(PortSpec{std::move(name),
                       std::string(T::kTypeName),
                       {},
                       flag == PortFlag::optional,
                       std::move(doc)});
  }
  // An input accepting every message type (pass-through, generic sinks, flow control).
  void input_any(std::string name, std::string doc = {}, PortFlag flag = PortFlag::required) {
    add_input(PortSpec{std::move(name), {}, {}, flag == PortFlag::optional, std::move(doc)});
  }
  // A repeated input: a graph wires min_count..max_count edges to it as name:0, name:1, ... (no
  // gaps); the node reads them with ctx.input<T>(name, i) and ctx.input_count(name). With
  // min_count 0 it may stay unconnected.
  template <class T>
  void inputs(std::string name, std::string doc, std::size_t min_count, std::size_t max_count) {
    add_input(PortSpec{std::move(name),
                       std::string(T::kTypeName),
                       {},
                       min_count == 0,
                       std::move(doc),
                       true,
                       min_count,
                       max_count});
  }

  // A repeated input accepting every message type (a generic joining sink).
  void inputs_any(std::string name, std::string doc, std::size_t min_count, std::size_t max_count) {
    add_input(PortSpec{
        std::move(name), {}, {}, min_count == 0, std::move(doc), true, min_count, max_count});
  }

  template <class T>
  void output(std::string name, std::string doc = {}) {
    add_output(PortSpec{std::move(name), std::string(T::kTypeName), {}, false, std::move(doc)});
  }
  // A repeated output: one stream per edge of the repeated input `input_name` (name:i goes with
  // input edge i; a node sends on it with ctx.send(name, i, message)). For nodes that treat each
  // of several streams alike (a limiter of camera frames).
  template <class T>
  void outputs(std::string name, std::string doc, std::string input_name) {
    PortSpec port{std::move(name), std::string(T::kTypeName), {}, false, std::move(doc)};
    port.repeated = true;
    port.per_edge_of = std::move(input_name);
    add_output(std::move(port));
  }
  // An output carrying whatever type the graph connects to input `input_name`.
  void output_same_as(std::string name, std::string input_name, std::string doc = {}) {
    add_output(PortSpec{std::move(name), {}, std::move(input_name), false, std::move(doc)});
  }

  template <class T>
  void param(std::string name, T fallback, std::string doc, Range range = {}) {
    add_param(ParamSpec{
        std::move(name), param_type_of<T>(), false, {}, to_value(fallback), range, std::move(doc)});
  }
  // A parameter every graph must set (a file path, an endpoint).
  template <class T>
  void required_param(std::string name, std::string doc, Range range = {}) {
    add_param(ParamSpec{
        std::move(name), param_type_of<T>(), false, {}, std::nullopt, range, std::move(doc)});
  }
  // A string limited to `choices`; graph validation names the allowed values and the nearest one.
  void param_choice(std::string name, std::string fallback, std::vector<std::string> choices,
                    std::string doc) {
    add_param(ParamSpec{std::move(name),
                        ParamType::string,
                        false,
                        std::move(choices),
                        ParamValue(std::move(fallback)),
                        {},
                        std::move(doc)});
  }
  // A list of values (a YAML sequence in a graph file, a comma list with --set); read it with
  // ctx.param<std::vector<T>>(name). Ranges apply to every item.
  template <class T>
  void param_list(std::string name, std::vector<T> fallback, std::string doc, Range range = {}) {
    static_assert(param_type_of<T>() != ParamType::boolean, "lists of bool are not supported");
    add_param(ParamSpec{
        std::move(name), param_type_of<T>(), true, {}, to_list(fallback), range, std::move(doc)});
  }
  // A list whose items are each one of `choices`.
  void param_choice_list(std::string name, std::vector<std::string> fallback,
                         std::vector<std::string> choices, std::string doc) {
    add_param(ParamSpec{std::move(name),
                        ParamType::string,
                        true,
                        std::move(choices),
                        ParamValue(std::move(fallback)),
                        {},
                        std::move(doc)});
  }

  // Joins the named inputs (JoinSpec above): process() sees one set per call, each input of it
  // present or missing (ctx.has). Declare the inputs first; one join per node.
  void join(JoinSpec spec);
  const std::optional<JoinSpec>& joined() const { return join_; }
  bool is_joined(std::string_view input) const;

  // The node opens a ZeroMQ socket itself, at the endpoint in parameter `endpoint_param`; it binds
  // unless `bind_param` names a bool parameter set to false. This adds the parameters
  // `curve_server` and `curve_client` (key file references, docs/security.md), and validation
  // applies the network rules to the endpoint (loopback unless allowed; keys beyond loopback) and
  // resolves the references, which the node hands to load_curve_keys (graph/keys.hpp).
  void network_socket(std::string endpoint_param, std::string bind_param = {});

  // The node serves HTTP (a page, WebSocket streams) with no authentication on the address in
  // parameter `host_param`: validation refuses anything but loopback unless the graph says
  // `allow_network: true`.
  void serves_http(std::string host_param) { http_host_param_ = std::move(host_param); }
  const std::string& http_host_param() const { return http_host_param_; }

  // Sources only: instead of ending by itself, the node runs until every node that does not
  // depend on it has finished (a statistics reporter, a heartbeat).
  void runs_until_graph_ends() { auxiliary_ = true; }

  const std::string& doc() const { return doc_; }
  const std::vector<PortSpec>& inputs() const { return inputs_; }
  const std::vector<PortSpec>& outputs() const { return outputs_; }
  const std::vector<ParamSpec>& params() const { return params_; }
  bool auxiliary() const { return auxiliary_; }
  struct NetworkSocket {
    std::string endpoint_param, bind_param;
  };
  const std::optional<NetworkSocket>& network() const { return network_; }
  bool is_source() const { return inputs_.empty(); }

  int input_index(std::string_view name) const;   // -1 when unknown
  int output_index(std::string_view name) const;  // -1 when unknown
  const ParamSpec* find_param(std::string_view name) const;

 private:
  template <class T>
  static ParamValue to_value(const T& v) {
    if constexpr (param_type_of<T>() == ParamType::boolean) {
      return ParamValue(static_cast<bool>(v));
    } else if constexpr (param_type_of<T>() == ParamType::integer) {
      return ParamValue(static_cast<std::int64_t>(v));
    } else if constexpr (param_type_of<T>() == ParamType::number) {
      return ParamValue(static_cast<double>(v));
    } else {
      return ParamValue(std::string(v));
    }
  }
  template <class T>
  static ParamValue to_list(const std::vector<T>& items) {
    if constexpr (param_type_of<T>() == ParamType::integer) {
      return ParamValue(std::vector<std::int64_t>(items.begin(), items.end()));
    } else if constexpr (param_type_of<T>() == ParamType::number) {
      return ParamValue(std::vector<double>(items.begin(), items.end()));
    } else {
      return ParamValue(std::vector<std::string>(items.begin(), items.end()));
    }
  }
  // These throw std::logic_error on duplicate names or a bad same_as: a bug in the node's code.
  void add_input(PortSpec port);
  void add_output(PortSpec port);
  void add_param(ParamSpec param);

  std::string doc_;
  std::vector<PortSpec> inputs_, outputs_;
  std::vector<ParamSpec> params_;
  bool auxiliary_ = false;
  std::optional<NetworkSocket> network_;
  std::string http_host_param_;
  std::optional<JoinSpec> join_;
};

}  // namespace mocap::graph
