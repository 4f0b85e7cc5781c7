#pragma once
// A graph as written in a graph file, before it is checked against the node types: nodes with
// their parameters as text, edges with policy and transport, placement into processes. Every
// item remembers where it was written so errors can name file and line.

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::graph {

struct SourceLocation {
  std::string file;
  int line = 0;  // 1-based; 0 when not from a file (command line)

  std::string str() const { return line > 0 ? file + ":" + std::to_string(line) : file; }
};

enum class PolicyKind { blocking, latest, drop_oldest };

struct EdgePolicy {
  PolicyKind kind = PolicyKind::blocking;
  std::size_t capacity = 16;  // latest: always 1

  std::string str() const;
  bool lossy() const { return kind != PolicyKind::blocking; }
};

// "blocking", "blocking(64)", "latest", "drop_oldest", "drop_oldest(4)"; nullopt when malformed.
std::optional<EdgePolicy> parse_policy(std::string_view text);

// "view" or "view:2": an input and, for a repeated one, the edge index (index < 0: none). Built
// by appending: GCC 12 warns (-Wrestrict, a false positive) on ":" + std::to_string(i).
inline std::string indexed_port(std::string_view port, long index) {
  std::string text(port);
  if (index >= 0) text.append(":").append(std::to_string(index));
  return text;
}

struct PortRef {
  std::string node, port;
  int index = -1;  // edge index of a repeated input ("solve.view:2"); -1: none written

  std::string str() const { return node + "." + indexed_port(port, index); }
};

// ZeroMQ CURVE of an edge (`curve: { server: keys/solve, client: keys/capture }`): key file
// references (graph/keys.hpp), already resolved against the graph file's folder. The consumer
// binds and is the server (SERVER.key; it lets in only the CLIENT.pub keys, or every *.pub of a
// client folder); the producer connects with SERVER.pub and CLIENT.key.
struct CurveSpec {
  std::string server;
  std::vector<std::string> clients;
  SourceLocation where;

  bool enabled() const { return !server.empty(); }
};

struct EdgeSpec {
  PortRef from, to;
  EdgePolicy policy;
  std::string transport;  // empty: in-process; else a ZeroMQ endpoint (inproc://, ipc://, tcp://)
  CurveSpec curve;        // keys of a transport edge; disabled when not given
  SourceLocation where;

  std::string str() const { return from.str() + " -> " + to.str(); }
};

struct ParamText {
  std::string text;  // a single value, or a comma list (--set) for a list parameter
  SourceLocation where;
  bool is_list = false;  // written as a YAML sequence: the items are in `items`
  std::vector<std::string> items{};
};

struct NodeSpec {
  std::string name, type;
  std::map<std::string, ParamText> params;
  SourceLocation where;
};

struct ProcessSpec {
  std::string name;
  std::vector<std::string> nodes;
  SourceLocation where;
};

struct PluginSpec {
  std::string path;  // resolved against the graph file's directory
  SourceLocation where;
};

struct GraphSpec {
  std::string name;
  std::string file;
  std::vector<NodeSpec> nodes;
  std::vector<EdgeSpec> edges;
  std::vector<ProcessSpec> processes;
  std::vector<PluginSpec> plugins;
  bool allow_network = false;  // tcp:// endpoints beyond loopback need `allow_network: true`
  // Set by `mocap run --process NAME` before validation: only the key files this process reads
  // are checked (the other ends may be on other hosts with their own files). Empty: all.
  std::string local_process;

  const NodeSpec* find_node(std::string_view name) const;
  // The process a node is placed in; empty when the graph has no placement.
  std::string process_of(std::string_view node) const;
};

// Reads a graph file. Throws mocap::InputError with file and line on bad YAML or structure.
GraphSpec load_graph_file(const std::string& path);
GraphSpec parse_graph_text(const std::string& text, const std::string& file_name);

// Applies `node.param=value` overrides (from --set). Throws InputError for malformed overrides or
// unknown nodes; unknown parameters are caught by validation like those in the file.
void apply_overrides(GraphSpec& graph, const std::vector<std::string>& overrides);

}  // namespace mocap::graph
