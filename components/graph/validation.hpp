#pragma once
// Checks a GraphSpec against the registered node types before anything runs: unknown types,
// ports and parameters, type mismatches, missing required parameters, cycles, placement. Every
// problem is reported with file and line, all of them at once.

#include <map>
#include <string>
#include <vector>

#include "graph/graph_spec.hpp"
#include "graph/params.hpp"
#include "graph/registry.hpp"

namespace mocap::graph {

struct ResolvedNode {
  std::string name;
  const NodeType* type = nullptr;
  std::map<std::string, ParamValue> params;  // every declared parameter, defaults filled in
  std::vector<std::string> input_types;      // per input port; "" while unconnected "any"
  std::vector<std::size_t> input_counts;     // per input port: edges wired to it (repeated: N)
  std::vector<std::string> output_types;     // per output port, after same_as is resolved
  std::string process;                       // empty when the graph has no placement
};

struct ResolvedGraph {
  GraphSpec spec;
  std::vector<ResolvedNode> nodes;  // in topological order (producers before consumers)

  const ResolvedNode* find(std::string_view name) const;
};

// A node's parameters from their text (a graph file, --set, the test harness): parsed as the
// declared types, checked against ranges and choices, defaults filled in. Each problem is
// appended to `errors` as "file:line: ..." (a near miss gets a "did you mean").
std::map<std::string, ParamValue> resolve_params(const NodeSpec& node, const Contract& contract,
                                                 std::vector<std::string>& errors);

// Loads the graph's plugins, then validates. Throws mocap::InputError whose message lists every
// problem, one per line, each starting with file:line.
ResolvedGraph resolve(GraphSpec spec, const Registry& registry = Registry::instance());

// Graphviz text of a graph: nodes grouped by process, edges labelled with policy and transport.
std::string to_dot(const ResolvedGraph& graph);
// gst-inspect-like description of a node type.
std::string describe(const NodeType& type);

}  // namespace mocap::graph
