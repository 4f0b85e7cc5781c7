// Fuzz target: graph files (graph/graph_spec.hpp parse_graph_text, then graph/validation.hpp
// resolve against the node types linked into this target: flow.pass_through, flow.limiter,
// flow.test_delay, test.counter, test.frames, test.collect). Plugins named by the input are not
// loaded: a fuzz input must not make the target open shared libraries.

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "graph/graph_spec.hpp"
#include "graph/validation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap;
  const std::string name = "fuzz-input.yaml";
  graph::GraphSpec spec;
  try {
    spec = graph::parse_graph_text(std::string(fuzz::text(data, size)), name);
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
    return 0;
  }
  spec.plugins.clear();
  try {
    const graph::ResolvedGraph resolved = graph::resolve(std::move(spec));
    fuzz::check(resolved.nodes.size() == resolved.spec.nodes.size(),
                "a resolved graph lost or gained nodes");
    (void)graph::to_dot(resolved);
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
  return 0;
}
