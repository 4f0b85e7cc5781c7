#pragma once
// Runs a resolved graph in this process until its streams end or SIGINT/SIGTERM (first signal:
// drain and flush; second: exit at once). Shared by `mocap run` and `mocap reconstruct`.

#include <string>

#include "graph/runtime.hpp"

namespace mocap::cli {

graph::RunResult run_graph_here(const graph::ResolvedGraph& graph, graph::RunOptions options,
                                const std::string& label);

}  // namespace mocap::cli
