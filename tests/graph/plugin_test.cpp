// Plugins: a shared library built by the tests registers a node type when loaded, and a graph
// can then use it.

#include <gtest/gtest.h>

#include "graph/plugins.hpp"
#include "graph/runtime.hpp"
#include "graph_test_util.hpp"

namespace mocap::graph {
namespace {

TEST(Plugins, ANodeTypeFromAPluginLoadsAndRuns) {
  load_plugin(MOCAP_TEST_PLUGIN);
  load_plugin(MOCAP_TEST_PLUGIN);  // loading twice is harmless
  const NodeType* tag = Registry::instance().find("plugin.tag");
  ASSERT_NE(tag, nullptr);
  EXPECT_NE(tag->origin.find("tag_plugin"), std::string::npos);
  testing::TempDir dir;
  Runtime runtime(
      resolve(parse_graph_text("nodes:\n  src: { type: test.counter, params: { count: 3 } }\n"
                               "  tag: { type: plugin.tag, params: { stream: relabelled } }\n"
                               "  sink: { type: test.collect, params: { path: " +
                                   dir.file("out.txt") +
                                   " } }\n"
                                   "edges:\n  - [src.out, tag.in]\n  - [tag.out, sink.in]\n",
                               "p.yaml")));
  ASSERT_TRUE(runtime.run().ok);
  const auto lines = testing::read_lines(dir.file("out.txt"));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(testing::fields(lines[2])[0], "relabelled");
}

TEST(Plugins, NotAPluginIsRefusedWithTheFileName) {
  try {
    load_plugin("/nonexistent/libnothing.so");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/libnothing.so"), std::string::npos);
  }
  try {
    load_plugin("libz.so.1");  // a real shared library without MOCAP_PLUGIN()
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a mocap plugin"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mocap::graph
