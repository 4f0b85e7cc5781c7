#pragma once
// Runs a resolved graph in this process until its streams end or SIGINT/SIGTERM (first signal:
// drain and flush; second: exit at once). Shared by `mocap run`, `mocap view` and `mocap
// reconstruct`.

#include <chrono>
#include <functional>
#include <string>

#include "graph/runtime.hpp"

namespace mocap::cli {

// `progress`, when given, is called with the graph's statistics every `every` while it runs (from
// another thread; not after this function returns).
using ProgressCallback = std::function<void(const graph::GraphStats&)>;

// Throws InputError naming the node, address and port when a node of this process that serves
// HTTP (sink.web) could not listen on its port (in use, not allowed): checked before anything
// starts, so that no sink has touched its files. Called by run_graph_here.
void check_ports_free(const graph::ResolvedGraph& graph, const graph::RunOptions& options);

graph::RunResult run_graph_here(const graph::ResolvedGraph& graph, graph::RunOptions options,
                                const std::string& label, const ProgressCallback& progress = {},
                                std::chrono::milliseconds every = std::chrono::milliseconds(250));

}  // namespace mocap::cli
