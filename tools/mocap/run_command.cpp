// `mocap run GRAPH`: validates a graph, runs it to the end of its streams or until SIGINT/SIGTERM
// (which drain it and flush the sinks), and prints per-node statistics. A graph with placement
// runs under a supervisor, one child process per group; `--process NAME` runs one group.

#include <iostream>
#include <mutex>

#include "cli_args.hpp"
#include "commands.hpp"
#include "core/install_paths.hpp"
#include "graph/plugins.hpp"
#include "graph/runtime.hpp"
#include "graph/signals.hpp"
#include "graph/supervisor.hpp"
#include "graph_runner.hpp"

namespace mocap::cli {
namespace {

using namespace mocap::graph;

std::string this_program() { return executable_path().string(); }

int run_here(const ResolvedGraph& graph, const Args& args) {
  const std::string label =
      args.has("process") ? "mocap run [" + args.get("process") + "]" : "mocap run";
  RunOptions options;
  options.process = args.get("process");
  options.single_process = args.has("single-process");
  options.drain_timeout = std::chrono::milliseconds(args.integer("drain-timeout"));
  const RunResult result = run_graph_here(graph, options, label);
  if (!args.has("quiet")) std::cerr << format_stats_table(result.stats);
  if (!result.ok) {
    std::cerr << label << ": " << result.error << "\n";
    return 1;
  }
  return 0;
}

int supervise(const ResolvedGraph& graph, const Args& args) {
  SupervisorOptions options;
  options.program = this_program();
  options.args = {"run", args.positionals()[0], "--drain-timeout", args.get("drain-timeout")};
  for (const std::string& set : args.all("set"))
    options.args.insert(options.args.end(), {"--set", set});
  if (args.has("quiet")) options.args.push_back("--quiet");
  options.max_restarts = static_cast<int>(args.integer("max-restarts"));
  std::vector<std::string> groups;
  for (const ProcessSpec& p : graph.spec.processes) groups.push_back(p.name);
  Supervisor supervisor(groups, options);
  SignalWatcher watcher([&](int, int) {
    std::cerr << "supervisor: stopping every group\n";
    supervisor.request_stop();
  });
  return supervisor.run();
}

}  // namespace

int run_command(int argc, char** argv) {
  Args args(
      "mocap run GRAPH [--set node.param=value ...] [--process NAME]",
      "Runs a graph file until its sources end or SIGINT/SIGTERM, then flushes the sinks and\n"
      "prints per-node statistics. A graph with `processes:` runs one child process per group\n"
      "under a supervisor that restarts a group that dies.");
  args.positional("GRAPH", "graph file (YAML, see docs/graph-files.md)")
      .option("set", "NODE.PARAM=VALUE", "override a node parameter", std::nullopt, true)
      .option("process", "NAME", "run only this process group of the graph")
      .flag("single-process", "run every node here, ignoring placement and edge transports")
      .option("max-restarts", "N", "restarts of a dead process group before giving up", "5",
              Range::count(0, 1'000'000))
      .option("drain-timeout", "MS",
              "after a stop, how long to go on processing what is queued and to wait for other "
              "processes; then the rest is counted and left",
              "1500", Range::count(0, 3'600'000))
      .flag("quiet", "do not print statistics at the end");
  int exit_code = 0;
  if (!args.parse(argc, argv, exit_code)) return exit_code;
  if (!follow_supervisor()) return 1;

  load_plugins_from_environment();
  GraphSpec spec = load_graph_file(args.positionals()[0]);
  apply_overrides(spec, args.all("set"));
  spec.local_process = args.get("process");  // key files: only those this process reads
  const ResolvedGraph graph = resolve(std::move(spec));
  for (const std::string& problem : Registry::instance().problems())
    std::cerr << "warning: " << problem << "\n";
  const bool supervised =
      !graph.spec.processes.empty() && !args.has("process") && !args.has("single-process");
  return supervised ? supervise(graph, args) : run_here(graph, args);
}

}  // namespace mocap::cli
