#pragma once
// What a node type declares about itself, statically: input and output ports with their message
// types and parameters with type, default, range and a one-line doc. The framework checks graphs
// against contracts before any node runs, and `mocap graph inspect` prints them.

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

  bool any() const { return type.empty() && same_as.empty(); }
};

enum class PortFlag { required, optional };

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

  template <class T>
  void output(std::string name, std::string doc = {}) {
    add_output(PortSpec{std::move(name), std::string(T::kTypeName), {}, false, std::move(doc)});
  }
  // An output carrying whatever type the graph connects to input `input_name`.
  void output_same_as(std::string name, std::string input_name, std::string doc = {}) {
    add_output(PortSpec{std::move(name), {}, std::move(input_name), false, std::move(doc)});
  }

  template <class T>
  void param(std::string name, T fallback, std::string doc, Range range = {}) {
    add_param(
        ParamSpec{std::move(name), param_type_of<T>(), to_value(fallback), range, std::move(doc)});
  }
  // A parameter every graph must set (a file path, an endpoint).
  template <class T>
  void required_param(std::string name, std::string doc, Range range = {}) {
    add_param(ParamSpec{std::move(name), param_type_of<T>(), std::nullopt, range, std::move(doc)});
  }

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
};

}  // namespace mocap::graph
