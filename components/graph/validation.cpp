#include "graph/validation.hpp"

#include <algorithm>
#include <filesystem>
#include <regex>
#include <set>
#include <sstream>

#include "core/input_error.hpp"
#include "graph/keys.hpp"
#include "graph/plugins.hpp"
#include "graph/transport.hpp"

namespace mocap::graph {

const ResolvedNode* ResolvedGraph::find(std::string_view name) const {
  for (const auto& node : nodes) {
    if (node.name == name) return &node;
  }
  return nullptr;
}

std::map<std::string, ParamValue> resolve_params(const NodeSpec& spec, const Contract& contract,
                                                 std::vector<std::string>& errors) {
  std::map<std::string, ParamValue> params;
  const auto error = [&](const SourceLocation& where, const std::string& what) {
    errors.push_back(where.str() + ": " + what);
  };
  for (const auto& [name, text] : spec.params) {
    const ParamSpec* param = contract.find_param(name);
    if (!param) {
      std::vector<std::string> known;
      for (const ParamSpec& p : contract.params()) known.push_back(p.name);
      const std::string near = nearest(name, known);
      error(text.where, "node '" + spec.name + "' (" + spec.type + ") has no parameter '" + name +
                            "'" + (near.empty() ? "" : "; did you mean '" + near + "'?"));
      continue;
    }
    try {
      params[name] =
          text.is_list ? parse_param_items(*param, text.items) : parse_param(*param, text.text);
    } catch (const std::invalid_argument& e) {
      error(text.where, "node '" + spec.name + "': " + e.what());
    }
  }
  for (const ParamSpec& param : contract.params()) {
    if (params.count(param.name) || spec.params.count(param.name)) continue;
    if (param.required()) {
      error(spec.where, "node '" + spec.name + "' (" + spec.type + ") needs parameter '" +
                            param.name + "' (" + param.doc + ")");
    } else {
      params[param.name] = *param.fallback;
    }
  }
  return params;
}

namespace {

class Checker {
 public:
  Checker(GraphSpec& spec, const Registry& registry) : spec_(spec), registry_(registry) {}

  ResolvedGraph run() {
    load_plugins();
    resolve_nodes();
    check_edges();
    check_unconnected_inputs();
    std::vector<std::size_t> order = topological_order();
    resolve_types(order);
    check_placement();
    check_transports();
    check_network_nodes();
    check_http_servers();
    if (!errors_.empty()) {
      std::string message;
      for (const auto& e : errors_) message += (message.empty() ? "" : "\n") + e;
      throw InputError("", message);
    }
    ResolvedGraph graph{spec_, {}};
    for (std::size_t i : order) graph.nodes.push_back(std::move(nodes_[i]));
    return graph;
  }

 private:
  void error(const SourceLocation& where, const std::string& what) {
    errors_.push_back(where.str() + ": " + what);
  }

  void load_plugins() {
    for (const auto& plugin : spec_.plugins) {
      try {
        load_plugins_from(plugin.path);
      } catch (const std::exception& e) {
        error(plugin.where, e.what());
      }
    }
  }

  void resolve_nodes() {
    std::set<std::string> seen;
    static const std::regex name_pattern(R"([A-Za-z_][A-Za-z0-9_\-]*)");
    for (const NodeSpec& spec : spec_.nodes) {
      ResolvedNode node;
      node.name = spec.name;
      if (!seen.insert(spec.name).second)
        error(spec.where, "node '" + spec.name + "' defined twice");
      if (!std::regex_match(spec.name, name_pattern)) {
        error(spec.where, "node name '" + spec.name + "' may hold only letters, digits, _ and -");
      }
      node.type = registry_.find(spec.type);
      if (!node.type) {
        std::vector<std::string> known;
        for (const NodeType* type : registry_.all()) known.push_back(type->name);
        const std::string near = nearest(spec.type, known);
        error(spec.where, "node '" + spec.name + "': unknown node type '" + spec.type + "' (" +
                              (near.empty() ? "" : "did you mean '" + near + "'? ") +
                              "see 'mocap graph inspect')");
      } else {
        resolve_params(spec, node);
        node.input_types.resize(node.type->contract.inputs().size());
        node.input_counts.resize(node.type->contract.inputs().size());
        node.output_types.resize(node.type->contract.outputs().size());
      }
      node.process = spec_.process_of(spec.name);
      nodes_.push_back(std::move(node));
    }
  }

  void resolve_params(const NodeSpec& spec, ResolvedNode& node) {
    node.params = graph::resolve_params(spec, node.type->contract, errors_);
  }

  int node_index(const std::string& name) const {
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      if (nodes_[i].name == name) return static_cast<int>(i);
    }
    return -1;
  }

  // Returns the port index, or -1 after reporting the problem.
  int port_index(const EdgeSpec& edge, const PortRef& ref, bool output) {
    const int n = node_index(ref.node);
    if (n < 0) {
      error(edge.where, "edge " + edge.str() + ": no node '" + ref.node + "'");
      return -1;
    }
    const NodeType* type = nodes_[static_cast<std::size_t>(n)].type;
    if (!type) return -1;  // unknown type, already reported
    const Contract& c = type->contract;
    const int port = output ? c.output_index(ref.port) : c.input_index(ref.port);
    if (port < 0) {
      std::string known;
      for (const auto& p : output ? c.outputs() : c.inputs())
        known += (known.empty() ? "" : ", ") + p.name;
      error(edge.where, "edge " + edge.str() + ": node '" + ref.node + "' (" + type->name +
                            ") has no " + (output ? "output" : "input") + " '" + ref.port + "' (" +
                            (output ? "outputs" : "inputs") + ": " +
                            (known.empty() ? "none" : known) + ")");
    }
    return port;
  }

  void check_edges() {
    std::map<std::string, const EdgeSpec*> input_used;
    for (const EdgeSpec& edge : spec_.edges) {
      const int out = port_index(edge, edge.from, true);
      const int in = port_index(edge, edge.to, false);
      if (out < 0 || in < 0) continue;
      const ResolvedNode& from = nodes_[static_cast<std::size_t>(node_index(edge.from.node))];
      const PortSpec& out_port = from.type->contract.outputs()[static_cast<std::size_t>(out)];
      if (!out_port.repeated && edge.from.index >= 0) {
        error(edge.where, "edge " + edge.str() + ": an output takes no index (" + edge.from.node +
                              "." + edge.from.port + ")");
        continue;
      }
      if (out_port.repeated && edge.from.index < 0) {
        error(edge.where, "edge " + edge.str() + ": " + edge.from.str() +
                              " is a repeated output (one stream per edge of input " +
                              out_port.per_edge_of + "): name the stream, " + edge.from.str() +
                              ":0, " + edge.from.str() + ":1, ...");
        continue;
      }
      ResolvedNode& to = nodes_[static_cast<std::size_t>(node_index(edge.to.node))];
      const PortSpec& port = to.type->contract.inputs()[static_cast<std::size_t>(in)];
      if (port.repeated && edge.to.index < 0) {
        error(edge.where, "edge " + edge.str() + ": " + edge.to.str() +
                              " is a repeated input: wire each edge to an index, " + edge.to.str() +
                              ":0, " + edge.to.str() + ":1, ...");
        continue;
      }
      if (!port.repeated && edge.to.index >= 0) {
        error(edge.where, "edge " + edge.str() + ": input " + edge.to.node + "." + edge.to.port +
                              " takes one edge, without an index");
        continue;
      }
      if (const auto [it, fresh] = input_used.emplace(edge.to.str(), &edge); !fresh) {
        error(edge.where, "input " + edge.to.str() + " is already fed by the edge at " +
                              it->second->where.str() + " (one edge per input)");
        continue;
      }
      ++to.input_counts[static_cast<std::size_t>(in)];
      valid_edges_.push_back(&edge);
    }
    check_repeated_inputs();
    check_repeated_outputs();
  }

  // Stream i of a repeated output goes with edge i of its input: there are as many as that
  // input has edges.
  void check_repeated_outputs() {
    for (const EdgeSpec* edge : valid_edges_) {
      const ResolvedNode& from = nodes_[static_cast<std::size_t>(node_index(edge->from.node))];
      const Contract& c = from.type->contract;
      const PortSpec& port = c.outputs()[static_cast<std::size_t>(c.output_index(edge->from.port))];
      if (!port.repeated) continue;
      const std::size_t streams =
          from.input_counts[static_cast<std::size_t>(c.input_index(port.per_edge_of))];
      if (static_cast<std::size_t>(edge->from.index) < streams) continue;
      const std::string input = from.name + "." + port.per_edge_of;
      error(edge->where,
            "edge " + edge->str() + ": " + edge->from.str() + " has no stream: " + from.name + "." +
                port.name + " has one per edge of " + input + " (" + std::to_string(streams) +
                ": " +
                (streams ? from.name + "." + port.name + ":0.." + std::to_string(streams - 1)
                         : std::string("none")) +
                ")");
    }
    std::erase_if(valid_edges_, [&](const EdgeSpec* edge) {
      const ResolvedNode& from = nodes_[static_cast<std::size_t>(node_index(edge->from.node))];
      const Contract& c = from.type->contract;
      const PortSpec& port = c.outputs()[static_cast<std::size_t>(c.output_index(edge->from.port))];
      return port.repeated &&
             static_cast<std::size_t>(edge->from.index) >=
                 from.input_counts[static_cast<std::size_t>(c.input_index(port.per_edge_of))];
    });
  }

  // A repeated input's edges are numbered 0..N-1 without gaps, with N within its bounds.
  void check_repeated_inputs() {
    for (const ResolvedNode& node : nodes_) {
      if (!node.type) continue;
      const Contract& c = node.type->contract;
      for (std::size_t i = 0; i < c.inputs().size(); ++i) {
        const PortSpec& port = c.inputs()[i];
        if (!port.repeated) continue;
        std::vector<const EdgeSpec*> by_index;
        for (const EdgeSpec* edge : valid_edges_) {
          if (edge->to.node != node.name || edge->to.port != port.name) continue;
          const auto index = static_cast<std::size_t>(edge->to.index);
          if (by_index.size() <= index) by_index.resize(index + 1, nullptr);
          by_index[index] = edge;
        }
        const std::string name = node.name + "." + port.name;
        for (std::size_t k = 0; k < by_index.size(); ++k) {
          if (by_index[k]) continue;
          const EdgeSpec* after = *std::find_if(by_index.begin() + static_cast<std::ptrdiff_t>(k),
                                                by_index.end(), [](auto* e) { return e; });
          error(after->where, "input " + indexed_port(name, static_cast<long>(k)) +
                                  " is not connected, but " + after->to.str() +
                                  " is (number the edges of " + name + " 0.." +
                                  std::to_string(node.input_counts[i] - 1) + " without gaps)");
          break;
        }
        const std::size_t n = node.input_counts[i];
        if (n < port.min_count || n > port.max_count) {
          const SourceLocation& where =
              by_index.empty() ? spec_.find_node(node.name)->where : by_index.back()->where;
          error(where, "input " + name + " takes " + std::to_string(port.min_count) + " to " +
                           std::to_string(port.max_count) + " edges (" + name + ":0.." +
                           std::to_string(port.max_count - 1) + "), not " + std::to_string(n));
        }
      }
    }
  }

  void check_unconnected_inputs() {
    for (const ResolvedNode& node : nodes_) {
      if (!node.type) continue;
      for (const PortSpec& port : node.type->contract.inputs()) {
        if (port.optional || port.repeated) continue;
        const bool connected = std::any_of(
            spec_.edges.begin(), spec_.edges.end(),
            [&](const EdgeSpec& e) { return e.to.node == node.name && e.to.port == port.name; });
        if (!connected) {
          error(spec_.find_node(node.name)->where,
                "input " + node.name + "." + port.name + " is not connected");
        }
      }
    }
  }

  // Kahn's algorithm; nodes left over sit on a cycle.
  std::vector<std::size_t> topological_order() {
    std::vector<int> pending(nodes_.size(), 0);
    for (const EdgeSpec* e : valid_edges_)
      ++pending[static_cast<std::size_t>(node_index(e->to.node))];
    std::vector<std::size_t> order, ready;
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      if (pending[i] == 0) ready.push_back(i);
    }
    while (!ready.empty()) {
      const std::size_t n = ready.front();
      ready.erase(ready.begin());
      order.push_back(n);
      for (const EdgeSpec* e : valid_edges_) {
        if (e->from.node != nodes_[n].name) continue;
        const auto to = static_cast<std::size_t>(node_index(e->to.node));
        if (--pending[to] == 0) ready.push_back(to);
      }
    }
    for (const EdgeSpec* e : valid_edges_) {
      if (pending[static_cast<std::size_t>(node_index(e->to.node))] > 0 &&
          pending[static_cast<std::size_t>(node_index(e->from.node))] > 0) {
        error(e->where, "edge " + e->str() + " closes a cycle (graphs must be acyclic)");
        break;
      }
    }
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      if (pending[i] > 0) order.push_back(i);  // keep every node; the error is already reported
    }
    return order;
  }

  // Propagates message types along edges in topological order; checks each edge's types.
  void resolve_types(const std::vector<std::size_t>& order) {
    for (std::size_t n : order) {
      ResolvedNode& node = nodes_[n];
      if (!node.type) continue;
      const Contract& c = node.type->contract;
      for (std::size_t o = 0; o < c.outputs().size(); ++o) {
        const PortSpec& port = c.outputs()[o];
        node.output_types[o] =
            port.same_as.empty()
                ? port.type
                : node.input_types[static_cast<std::size_t>(c.input_index(port.same_as))];
      }
      for (const EdgeSpec* e : valid_edges_) {
        if (e->from.node != node.name) continue;
        ResolvedNode& to = nodes_[static_cast<std::size_t>(node_index(e->to.node))];
        const std::string& sent =
            node.output_types[static_cast<std::size_t>(c.output_index(e->from.port))];
        const int in = to.type->contract.input_index(e->to.port);
        const std::string& accepted = to.type->contract.inputs()[static_cast<std::size_t>(in)].type;
        if (!accepted.empty() && !sent.empty() && accepted != sent) {
          error(e->where, "edge " + e->str() + ": type mismatch, " + e->from.str() + " sends " +
                              sent + " but " + e->to.str() + " takes " + accepted);
        }
        to.input_types[static_cast<std::size_t>(in)] = accepted.empty() ? sent : accepted;
      }
    }
  }

  void check_placement() {
    if (spec_.processes.empty()) return;
    std::map<std::string, std::string> placed;
    std::set<std::string> process_names;
    for (const ProcessSpec& process : spec_.processes) {
      if (!process_names.insert(process.name).second) {
        error(process.where, "process '" + process.name + "' defined twice");
      }
      for (const std::string& member : process.nodes) {
        if (node_index(member) < 0)
          error(process.where, "process '" + process.name + "': no node '" + member + "'");
        if (const auto [it, fresh] = placed.emplace(member, process.name); !fresh) {
          error(process.where, "node '" + member + "' is placed in both '" + it->second +
                                   "' and '" + process.name + "'");
        }
      }
    }
    for (const NodeSpec& node : spec_.nodes) {
      if (!placed.count(node.name)) {
        error(node.where, "node '" + node.name + "' is not placed in any process");
      }
    }
    for (const EdgeSpec& edge : spec_.edges) {
      const std::string from = spec_.process_of(edge.from.node),
                        to = spec_.process_of(edge.to.node);
      if (from == to || from.empty() || to.empty()) continue;
      if (edge.transport.empty() || edge.transport.rfind("inproc://", 0) == 0) {
        error(edge.where, "edge " + edge.str() + " crosses from process '" + from + "' to '" + to +
                              "': give it an ipc:// or tcp:// transport");
      }
    }
  }

  // What an endpoint says about the network: tcp:// to anything but loopback leaves the machine
  // (`*`, 0.0.0.0 and [::] listen on every interface).
  struct Endpoint {
    bool tcp = false, malformed = false, beyond_loopback = false, inproc = false;
    std::string host;
  };
  static Endpoint endpoint_of(const std::string& text) {
    static const std::regex tcp(R"(tcp://(\[[^\]]+\]|[^:]+):(\d+|\*))");
    Endpoint e;
    e.inproc = text.rfind("inproc://", 0) == 0;
    if (text.rfind("tcp://", 0) != 0) return e;
    e.tcp = true;
    std::smatch match;
    if (!std::regex_match(text, match, tcp)) {
      e.malformed = true;
      return e;
    }
    e.host = match[1].str();
    e.beyond_loopback = !(e.host == "localhost" || e.host == "[::1]" ||
                          e.host.rfind("127.", 0) == 0 || e.host == "lo");
    return e;
  }

  bool local(const std::string& process) const {
    return spec_.local_process.empty() || process.empty() || process == spec_.local_process;
  }

  // Reads the key files an end of a CURVE socket will read, reporting every problem at `where`.
  void check_key_files(const SourceLocation& where, const std::string& server,
                       const std::vector<std::string>& clients, bool check_binder,
                       bool check_connector) {
    if (!curve_available()) {
      error(where,
            "CURVE keys are given, but this libzmq has no CURVE security (zmq_has(\"curve\") is "
            "false: install a libzmq built with libsodium)");
      return;
    }
    auto attempt = [&](auto&& read) {
      try {
        read();
      } catch (const std::exception& e) {
        error(where, e.what());
      }
    };
    if (check_binder) {
      attempt([&] { read_secret_key_file(server + ".key"); });
      for (const std::string& client : clients) attempt([&] { read_public_keys(client); });
    }
    if (check_connector) {
      attempt([&] { read_public_key_file(server + ".pub"); });
      if (clients.size() != 1) {
        error(where, "the connecting end needs exactly one client key (its own), not " +
                         std::to_string(clients.size()));
      } else {
        attempt([&] { read_secret_key_file(clients.front() + ".key"); });
      }
    }
  }

  void check_transports() {
    std::map<std::string, const EdgeSpec*> used;
    for (const EdgeSpec& edge : spec_.edges) {
      if (edge.transport.empty()) {
        if (edge.curve.enabled()) {
          error(edge.curve.where,
                "edge " + edge.str() + ": curve keys need an ipc:// or tcp:// transport");
        }
        continue;
      }
      if (const auto [it, fresh] = used.emplace(edge.transport, &edge); !fresh) {
        error(edge.where, "endpoint " + edge.transport + " is already used by the edge at " +
                              it->second->where.str());
      }
      const Endpoint endpoint = endpoint_of(edge.transport);
      if (endpoint.inproc && edge.curve.enabled()) {
        error(edge.curve.where,
              "edge " + edge.str() +
                  ": curve keys need an ipc:// or tcp:// transport, not inproc://");
      }
      if (endpoint.malformed) {
        error(edge.where, "tcp endpoint '" + edge.transport + "' must be tcp://host:port");
        continue;
      }
      if (endpoint.beyond_loopback && !spec_.allow_network) {
        error(edge.where, "edge " + edge.str() + " listens beyond this machine (" + endpoint.host +
                              "); set 'allow_network: true' in the graph to allow it");
      }
      if (endpoint.beyond_loopback && !edge.curve.enabled()) {
        error(edge.where, "edge " + edge.str() + " crosses the network (" + endpoint.host +
                              ") without keys: add curve: { server: KEYFILE, client: KEYFILE } "
                              "to it (see docs/security.md, 'mocap keys generate')");
      }
      if (edge.curve.enabled()) {
        check_key_files(edge.curve.where, edge.curve.server, edge.curve.clients,
                        local(spec_.process_of(edge.to.node)),
                        local(spec_.process_of(edge.from.node)));
      }
    }
  }

  // Nodes that open sockets themselves (Contract::network_socket): the same rules as edges, with
  // the keys in the parameters curve_server and curve_client.
  void check_network_nodes() {
    for (ResolvedNode& node : nodes_) {
      if (!node.type || !node.type->contract.network()) continue;
      const Contract::NetworkSocket& socket = *node.type->contract.network();
      const NodeSpec& spec = *spec_.find_node(node.name);
      const auto text = [&](const std::string& param) -> std::string {
        const auto it = node.params.find(param);
        if (it == node.params.end()) return {};
        const auto* value = std::get_if<std::string>(&it->second);
        return value ? *value : std::string();
      };
      const auto where = [&](const std::string& param) {
        const auto it = spec.params.find(param);
        return it == spec.params.end() ? spec.where : it->second.where;
      };
      const std::string endpoint_text = text(socket.endpoint_param);
      if (endpoint_text.empty()) continue;  // a missing required parameter, already reported
      bool binds = true;
      if (!socket.bind_param.empty()) {
        const auto it = node.params.find(socket.bind_param);
        if (it != node.params.end() && std::holds_alternative<bool>(it->second)) {
          binds = std::get<bool>(it->second);
        }
      }
      // Key references: relative ones against the graph file's folder (--set: the current one).
      std::vector<std::string> clients;
      std::string server;
      bool references_ok = true;
      const auto resolve_one = [&](const std::string& param, std::string reference) {
        const auto first = reference.find_first_not_of(" \t");
        const auto last = reference.find_last_not_of(" \t");
        reference = first == std::string::npos ? "" : reference.substr(first, last - first + 1);
        if (const std::string problem = key_reference_problem(reference); !problem.empty()) {
          error(where(param), "node '" + node.name + "': " + param + ": " + problem);
          references_ok = false;
          return std::string();
        }
        const SourceLocation at = where(param);
        const std::filesystem::path base =
            at.line > 0 ? std::filesystem::path(spec_.file).parent_path() : "";
        return resolve_key_reference(reference, base);
      };
      if (const std::string server_text = text("curve_server"); !server_text.empty()) {
        server = resolve_one("curve_server", server_text);
      }
      if (const auto it = node.params.find("curve_client"); it != node.params.end()) {
        if (const auto* items = std::get_if<std::vector<std::string>>(&it->second)) {
          for (const std::string& item : *items)
            clients.push_back(resolve_one("curve_client", item));
        }
      }
      if (!references_ok) continue;
      const bool curve = !server.empty();
      if (curve != !clients.empty()) {
        error(spec.where, "node '" + node.name +
                              "': curve_server and curve_client go together (the server's key "
                              "and the client keys)");
        continue;
      }
      node.params["curve_server"] = server;
      node.params["curve_client"] = clients;
      const Endpoint endpoint = endpoint_of(endpoint_text);
      if (endpoint.inproc && curve) {
        error(where("curve_server"),
              "node '" + node.name + "': curve keys need an ipc:// or tcp:// endpoint");
      }
      if (endpoint.beyond_loopback && !spec_.allow_network) {
        error(where(socket.endpoint_param),
              "node '" + node.name + "': " + endpoint_text + " reaches beyond this machine (" +
                  endpoint.host + "); set 'allow_network: true' in the graph to allow it");
      }
      if (endpoint.beyond_loopback && !curve) {
        error(where(socket.endpoint_param),
              "node '" + node.name + "': " + endpoint_text + " crosses the network (" +
                  endpoint.host +
                  ") without keys: set curve_server and curve_client (see docs/security.md, "
                  "'mocap keys generate')");
      }
      if (curve) {
        check_key_files(where("curve_server"), server, clients, binds && local(node.process),
                        !binds && local(node.process));
      }
    }
  }

  // Nodes that serve HTTP without authentication (Contract::serves_http): loopback unless allowed.
  void check_http_servers() {
    for (const ResolvedNode& node : nodes_) {
      if (!node.type || node.type->contract.http_host_param().empty()) continue;
      const std::string& param = node.type->contract.http_host_param();
      const auto it = node.params.find(param);
      const auto* host = it == node.params.end() ? nullptr : std::get_if<std::string>(&it->second);
      if (!host || is_loopback_host(*host) || spec_.allow_network) continue;
      const NodeSpec& spec = *spec_.find_node(node.name);
      const auto at = spec.params.find(param);
      error(at == spec.params.end() ? spec.where : at->second.where,
            "node '" + node.name + "': " + param + " " + *host +
                " serves the page beyond this machine, to anyone, without authentication; set "
                "'allow_network: true' in the graph to allow it");
    }
  }
  static bool is_loopback_host(const std::string& host) {
    return host == "localhost" || host == "::1" || host == "[::1]" || host.rfind("127.", 0) == 0;
  }

  GraphSpec& spec_;
  const Registry& registry_;
  std::vector<ResolvedNode> nodes_;
  std::vector<const EdgeSpec*> valid_edges_;
  std::vector<std::string> errors_;
};

}  // namespace

ResolvedGraph resolve(GraphSpec spec, const Registry& registry) {
  return Checker(spec, registry).run();
}

std::string to_dot(const ResolvedGraph& graph) {
  std::ostringstream out;
  out << "digraph \"" << (graph.spec.name.empty() ? "graph" : graph.spec.name) << "\" {\n"
      << "  rankdir=LR;\n  node [shape=box, fontname=\"Helvetica\"];\n";
  auto node_line = [&](const ResolvedNode& n, const char* indent) {
    out << indent << "\"" << n.name << "\" [label=\"" << n.name << "\\n"
        << n.type->name << "\"];\n";
  };
  for (const ProcessSpec& process : graph.spec.processes) {
    out << "  subgraph \"cluster_" << process.name << "\" {\n    label=\"" << process.name
        << "\";\n";
    for (const std::string& member : process.nodes) {
      if (const ResolvedNode* n = graph.find(member)) node_line(*n, "    ");
    }
    out << "  }\n";
  }
  for (const ResolvedNode& n : graph.nodes) {
    if (n.process.empty()) node_line(n, "  ");
  }
  for (const EdgeSpec& e : graph.spec.edges) {
    const ResolvedNode* from = graph.find(e.from.node);
    const auto port = static_cast<std::size_t>(from->type->contract.output_index(e.from.port));
    const std::string to_port = indexed_port(e.to.port, e.to.index);
    out << "  \"" << e.from.node << "\" -> \"" << e.to.node << "\" [label=\""
        << indexed_port(e.from.port, e.from.index) << " -> " << to_port << "\\n"
        << from->output_types[port] << ", " << e.policy.str()
        << (e.transport.empty() ? "" : "\\n" + e.transport) << "\""
        << (e.policy.lossy() ? ", style=dashed" : "") << "];\n";
  }
  out << "}\n";
  return out.str();
}

std::string describe(const NodeType& type) {
  std::ostringstream out;
  const Contract& c = type.contract;
  out << type.name << "\n  " << (c.doc().empty() ? "(no description)" : c.doc()) << "\n"
      << "  from: " << type.origin << "\n";
  auto port_type = [](const PortSpec& p) {
    return !p.type.empty()      ? p.type
           : !p.same_as.empty() ? "same as " + p.same_as
                                : std::string("any");
  };
  out << "\n  inputs:\n";
  if (c.inputs().empty()) out << "    (none: a source)\n";
  for (const auto& p : c.inputs()) {
    out << "    " << p.name;
    if (p.repeated) {
      out << ":0..N : " << port_type(p) << " (" << p.min_count << " to " << p.max_count
          << " edges)";
    } else {
      out << " : " << port_type(p) << (p.optional ? " (optional)" : "");
    }
    out << (c.is_joined(p.name) ? " (joined)" : "") << (p.doc.empty() ? "" : "  " + p.doc) << "\n";
  }
  if (const auto& join = c.joined()) {
    std::string ports;
    for (const std::string& port : join->ports) ports += (ports.empty() ? "" : " + ") + port;
    out << "    joined: " << ports << ", one set per "
        << (join->key == SyncKey::frame ? "frame number" : "capture time")
        << " (parameters sync_*)\n";
  }
  out << "\n  outputs:\n";
  if (c.outputs().empty()) out << "    (none: a sink)\n";
  for (const auto& p : c.outputs()) {
    out << "    " << p.name << (p.repeated ? ":0..N" : "") << " : " << port_type(p)
        << (p.repeated ? " (one per edge of " + p.per_edge_of + ")" : "")
        << (p.doc.empty() ? "" : "  " + p.doc) << "\n";
  }
  out << "\n  parameters:\n";
  if (c.params().empty()) out << "    (none)\n";
  for (const auto& p : c.params()) {
    out << "    " << p.name << " : " << p.type_text();
    if (p.fallback) {
      out << " = " << to_text(*p.fallback);
    } else {
      out << " (required)";
    }
    if (p.range.min || p.range.max) {
      out << " in [" << (p.range.min ? to_text(*p.range.min) : "-inf") << ", "
          << (p.range.max ? to_text(*p.range.max) : "inf") << "]";
    }
    out << "\n        " << p.doc << "\n";
  }
  return out.str();
}

}  // namespace mocap::graph
