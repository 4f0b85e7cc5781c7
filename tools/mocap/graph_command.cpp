// `mocap graph validate|inspect|dot`: check a graph file, list node types (like gst-inspect),
// export a graph for Graphviz.

#include <iostream>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/input_error.hpp"
#include "graph/plugins.hpp"
#include "graph/validation.hpp"

namespace mocap::cli {
namespace {

using namespace mocap::graph;

ResolvedGraph load(const std::string& path, const Args& args) {
  GraphSpec spec = load_graph_file(path);
  apply_overrides(spec, args.all("set"));
  return resolve(std::move(spec));
}

int validate(const std::vector<std::string>& operands, const Args& args) {
  if (operands.size() != 1) throw InputError("mocap graph validate", "expected one GRAPH file");
  const ResolvedGraph graph = load(operands[0], args);
  std::cout << operands[0] << ": ok (" << graph.nodes.size() << " nodes, "
            << graph.spec.edges.size() << " edges, " << graph.spec.processes.size()
            << " processes)\n";
  return 0;
}

int inspect(const std::vector<std::string>& operands) {
  if (operands.size() > 1) throw InputError("mocap graph inspect", "expected at most one TYPE");
  const Registry& registry = Registry::instance();
  if (operands.size() == 1) {
    const NodeType* type = registry.find(operands[0]);
    if (!type) {
      std::vector<std::string> known;
      for (const NodeType* t : registry.all()) known.push_back(t->name);
      const std::string near = nearest(operands[0], known);
      throw InputError("mocap graph inspect",
                       "unknown node type '" + operands[0] + "'" +
                           (near.empty() ? "" : "; did you mean '" + near + "'?"));
    }
    std::cout << describe(*type);
    return 0;
  }
  for (const NodeType* type : registry.all()) {
    std::string name = type->name;
    name.resize(std::max<std::size_t>(name.size() + 2, 22), ' ');
    std::cout << name << type->contract.doc() << "\n";
  }
  return 0;
}

int dot(const std::vector<std::string>& operands, const Args& args) {
  if (operands.size() != 1) throw InputError("mocap graph dot", "expected one GRAPH file");
  std::cout << to_dot(load(operands[0], args));
  return 0;
}

}  // namespace

int graph_command(int argc, char** argv) {
  Args args("mocap graph validate GRAPH | inspect [TYPE] | dot GRAPH",
            "validate: checks a graph file against the node types (every problem with file:line)\n"
            "inspect:  lists node types, or shows one type's ports and parameters\n"
            "dot:      prints the graph for Graphviz (mocap graph dot g.yaml | dot -Tsvg > g.svg)\n"
            "Plugins on MOCAP_PLUGIN_PATH and in the graph's plugins: list are loaded first.");
  args.positional("ACTION", "validate, inspect or dot")
      .positional("ARGS", "graph file or node type", true, false)
      .option("set", "NODE.PARAM=VALUE", "override a node parameter", std::nullopt, true);
  int exit_code = 0;
  if (!args.parse(argc, argv, exit_code)) return exit_code;
  load_plugins_from_environment();
  const std::string action = args.positionals()[0];
  const std::vector<std::string> operands(args.positionals().begin() + 1, args.positionals().end());
  if (action == "validate") return validate(operands, args);
  if (action == "inspect") return inspect(operands);
  if (action == "dot") return dot(operands, args);
  throw InputError("mocap graph", "unknown action '" + action + "' (validate, inspect, dot)");
}

}  // namespace mocap::cli
