// The only file that knows YAML: it turns a graph file into a GraphSpec, keeping line numbers.

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "core/input_error.hpp"
#include "graph/graph_spec.hpp"
#include "graph/keys.hpp"

namespace mocap::graph {

std::string EdgePolicy::str() const {
  switch (kind) {
    case PolicyKind::blocking:
      return "blocking(" + std::to_string(capacity) + ")";
    case PolicyKind::latest:
      return "latest";
    case PolicyKind::drop_oldest:
      return "drop_oldest(" + std::to_string(capacity) + ")";
  }
  return "?";
}

std::optional<EdgePolicy> parse_policy(std::string_view text) {
  static const std::regex pattern(
      R"(\s*(blocking|latest|drop_oldest)\s*(?:\(\s*(\d{1,7})\s*\))?\s*)");
  std::match_results<std::string_view::const_iterator> match;
  if (!std::regex_match(text.begin(), text.end(), match, pattern)) return std::nullopt;
  EdgePolicy policy;
  const std::string kind = match[1].str();
  policy.kind = kind == "blocking" ? PolicyKind::blocking
                : kind == "latest" ? PolicyKind::latest
                                   : PolicyKind::drop_oldest;
  if (match[2].matched) {
    if (policy.kind == PolicyKind::latest) return std::nullopt;  // latest keeps exactly one
    policy.capacity = std::stoul(match[2].str());
    if (policy.capacity == 0) return std::nullopt;
  }
  if (policy.kind == PolicyKind::latest) policy.capacity = 1;
  return policy;
}

const NodeSpec* GraphSpec::find_node(std::string_view node_name) const {
  for (const auto& node : nodes) {
    if (node.name == node_name) return &node;
  }
  return nullptr;
}

std::string GraphSpec::process_of(std::string_view node) const {
  for (const auto& process : processes) {
    for (const auto& member : process.nodes) {
      if (member == node) return process.name;
    }
  }
  return {};
}

namespace {

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  SourceLocation at(const YAML::Node& node) const {
    return {file_, node.Mark().is_null() ? 0 : node.Mark().line + 1};
  }
  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const {
    throw InputError(file_, at(node).line, what);
  }
  std::string scalar(const YAML::Node& node, const std::string& what) const {
    if (!node.IsScalar()) fail(node, what + " must be a single value");
    return node.Scalar();
  }
  void expect_map(const YAML::Node& node, const std::string& what) const {
    if (!node.IsMap()) fail(node, what + " must be a mapping (key: value)");
  }
  void only_keys(const YAML::Node& map, std::initializer_list<std::string_view> keys,
                 const std::string& what) const {
    for (const auto& item : map) {
      const std::string key = item.first.Scalar();
      if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
        fail(item.first, "unknown key '" + key + "' in " + what);
      }
    }
  }
  // node.port, or node.port:INDEX for an edge of a repeated input.
  PortRef port_ref(const YAML::Node& node) const {
    const std::string text = scalar(node, "an edge end");
    static const std::regex pattern(R"(([^.:]+)\.([^.:]+)(?::(\d{1,6}))?)");
    std::smatch match;
    if (!std::regex_match(text, match, pattern)) {
      fail(node, "edge end '" + text +
                     "' must be written node.port (or node.port:N for edge N "
                     "of a repeated input)");
    }
    return {match[1].str(), match[2].str(), match[3].matched ? std::stoi(match[3].str()) : -1};
  }

  NodeSpec node(const std::string& name, const YAML::Node& body) const {
    NodeSpec spec;
    spec.name = name;
    spec.where = at(body);
    expect_map(body, "node '" + name + "'");
    only_keys(body, {"type", "params"}, "node '" + name + "'");
    if (!body["type"]) fail(body, "node '" + name + "' has no type");
    spec.type = scalar(body["type"], "a node type");
    if (const YAML::Node params = body["params"]) {
      if (params.IsNull()) return spec;
      expect_map(params, "params of node '" + name + "'");
      for (const auto& item : params) spec.params[item.first.Scalar()] = param(item);
    }
    return spec;
  }

  // A single value, or a YAML sequence of single values for a list parameter.
  template <class Item>
  ParamText param(const Item& item) const {
    const std::string name = item.first.Scalar();
    ParamText text{{}, at(item.second)};
    if (!item.second.IsSequence()) {
      text.text = scalar(item.second, "parameter '" + name + "'");
      return text;
    }
    text.is_list = true;
    for (const auto& value : item.second) {
      text.items.push_back(scalar(value, "an item of parameter '" + name + "'"));
      text.text += (text.text.empty() ? "" : ",") + text.items.back();
    }
    return text;
  }

  void edge_options(const YAML::Node& options, EdgeSpec& edge) const {
    expect_map(options, "edge options");
    only_keys(options, {"policy", "transport", "curve", "from", "to"}, "an edge");
    if (const YAML::Node curve = options["curve"]) edge.curve = curve_spec(curve);
    if (const YAML::Node policy = options["policy"]) {
      const std::string text = scalar(policy, "policy");
      const auto parsed = parse_policy(text);
      if (!parsed) {
        fail(policy, "unknown edge policy '" + text +
                         "' (blocking, blocking(N), latest, drop_oldest, drop_oldest(N))");
      }
      edge.policy = *parsed;
    }
    if (const YAML::Node transport = options["transport"]) {
      edge.transport = scalar(transport, "transport");
      static const std::regex endpoint(R"((inproc|ipc|tcp)://.+)");
      if (edge.transport == "in-process") {
        edge.transport.clear();
      } else if (!std::regex_match(edge.transport, endpoint)) {
        fail(transport, "transport '" + edge.transport +
                            "' must be in-process or an inproc://, ipc:// or tcp:// endpoint");
      }
    }
  }

  std::string key_reference(const YAML::Node& node) const {
    const std::string text = scalar(node, "a key reference");
    if (const std::string problem = key_reference_problem(text); !problem.empty()) {
      fail(node, "curve: " + problem);
    }
    return resolve_key_reference(text, std::filesystem::path(file_).parent_path());
  }

  // curve: { server: REF, client: REF }
  CurveSpec curve_spec(const YAML::Node& node) const {
    CurveSpec spec;
    spec.where = at(node);
    if (!node.IsMap()) {
      fail(node, "curve must be { server: KEYFILE, client: KEYFILE } (key files, not keys)");
    }
    only_keys(node, {"server", "client"}, "curve");
    if (!node["server"] || !node["client"]) {
      fail(node, "curve needs server: (the consumer's key) and client: (the producer's key)");
    }
    spec.server = key_reference(node["server"]);
    // An edge has one producer, so one client key: it is both what the producer connects with
    // and the only key the consumer lets in.
    spec.clients.push_back(key_reference(node["client"]));
    return spec;
  }

  // [from, to] or [from, to, {options}] or {from: .., to: .., policy: .., transport: ..}
  EdgeSpec edge(const YAML::Node& item) const {
    EdgeSpec spec;
    spec.where = at(item);
    if (item.IsSequence()) {
      if (item.size() < 2 || item.size() > 3)
        fail(item, "an edge is [from.port, to.port, {options}]");
      spec.from = port_ref(item[0]);
      spec.to = port_ref(item[1]);
      if (item.size() == 3) edge_options(item[2], spec);
    } else if (item.IsMap()) {
      if (!item["from"] || !item["to"]) fail(item, "an edge needs from: and to:");
      spec.from = port_ref(item["from"]);
      spec.to = port_ref(item["to"]);
      edge_options(item, spec);
    } else {
      fail(item, "an edge is [from.port, to.port, {options}]");
    }
    return spec;
  }

  ProcessSpec process(const std::string& name, const YAML::Node& members) const {
    ProcessSpec spec{name, {}, at(members)};
    if (!members.IsSequence()) fail(members, "process '" + name + "' must list its nodes: [a, b]");
    for (const auto& member : members) spec.nodes.push_back(scalar(member, "a node name"));
    return spec;
  }

  GraphSpec graph(const YAML::Node& root) const {
    GraphSpec spec;
    spec.file = file_;
    if (!root.IsMap()) fail(root, "a graph file is a mapping with nodes: and edges:");
    only_keys(root, {"graph", "nodes", "edges", "processes", "plugins", "allow_network"},
              "the graph");
    if (root["graph"]) spec.name = scalar(root["graph"], "graph");
    if (root["allow_network"]) spec.allow_network = root["allow_network"].as<bool>(false);
    const YAML::Node nodes = root["nodes"];
    if (!nodes) fail(root, "the graph has no nodes:");
    expect_map(nodes, "nodes");
    for (const auto& item : nodes) spec.nodes.push_back(node(item.first.Scalar(), item.second));
    if (const YAML::Node edges = root["edges"]; edges && !edges.IsNull()) {
      if (!edges.IsSequence()) fail(edges, "edges: must be a list");
      for (const auto& item : edges) spec.edges.push_back(edge(item));
    }
    if (const YAML::Node processes = root["processes"]; processes && !processes.IsNull()) {
      expect_map(processes, "processes");
      for (const auto& item : processes) {
        spec.processes.push_back(process(item.first.Scalar(), item.second));
      }
    }
    if (const YAML::Node plugins = root["plugins"]; plugins && !plugins.IsNull()) {
      if (!plugins.IsSequence()) fail(plugins, "plugins: must be a list of files or directories");
      const auto base = std::filesystem::path(file_).parent_path();
      for (const auto& item : plugins) {
        const std::filesystem::path path = scalar(item, "a plugin path");
        spec.plugins.push_back({(path.is_absolute() ? path : base / path).string(), at(item)});
      }
    }
    return spec;
  }

 private:
  std::string file_;
};

}  // namespace

GraphSpec parse_graph_text(const std::string& text, const std::string& file_name) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(file_name, e.mark.is_null() ? 0 : e.mark.line + 1, e.msg);
  }
  const Reader reader(file_name);
  try {
    return reader.graph(root);
  } catch (const YAML::Exception& e) {  // a conversion failed (e.g. allow_network: maybe)
    throw InputError(file_name, e.mark.is_null() ? 0 : e.mark.line + 1, e.msg);
  }
}

GraphSpec load_graph_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot read the graph file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_graph_text(text.str(), path);
}

void apply_overrides(GraphSpec& graph, const std::vector<std::string>& overrides) {
  for (const std::string& item : overrides) {
    const auto eq = item.find('=');
    const auto dot = item.find('.');
    if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 ||
        dot + 1 == eq) {
      throw InputError("--set " + item, "expected node.param=value");
    }
    const std::string node_name = item.substr(0, dot);
    auto it = std::find_if(graph.nodes.begin(), graph.nodes.end(),
                           [&](const NodeSpec& n) { return n.name == node_name; });
    if (it == graph.nodes.end()) {
      throw InputError("--set " + item, "the graph has no node '" + node_name + "'");
    }
    it->params[item.substr(dot + 1, eq - dot - 1)] =
        ParamText{item.substr(eq + 1), SourceLocation{"--set " + item, 0}};
  }
}

}  // namespace mocap::graph
