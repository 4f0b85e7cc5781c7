#pragma once
// Runs a resolved graph in this process until its streams end or SIGINT/SIGTERM (first signal:
// drain and flush; second: exit at once). Shared by `mocap run` and `mocap reconstruct`.

#include <chrono>
#include <functional>
#include <string>

#include "graph/runtime.hpp"

namespace mocap::cli {

// `progress`, when given, is called with the graph's statistics every `every` while it runs (from
// another thread; not after this function returns).
using ProgressCallback = std::function<void(const graph::GraphStats&)>;

graph::RunResult run_graph_here(const graph::ResolvedGraph& graph, graph::RunOptions options,
                                const std::string& label, const ProgressCallback& progress = {},
                                std::chrono::milliseconds every = std::chrono::milliseconds(250));

}  // namespace mocap::cli
