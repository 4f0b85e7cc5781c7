#pragma once
// Running a small graph from a test, for the sink tests.

#include <string>

#include <gtest/gtest.h>

#include "graph/runtime.hpp"

namespace mocap::nodes::testing {

inline graph::RunResult run_graph(const std::string& yaml) {
  graph::Runtime runtime(graph::resolve(graph::parse_graph_text(yaml, "test.yaml")));
  return runtime.run();
}

inline const graph::NodeStats& stats_of(const graph::RunResult& result, const std::string& node) {
  for (const graph::NodeStats& s : result.stats.nodes) {
    if (s.node == node) return s;
  }
  throw std::runtime_error("no stats for " + node);
}

}  // namespace mocap::nodes::testing
