// Fuzz target: graph files (graph/graph_spec.hpp parse_graph_text, then graph/validation.hpp
// resolve against the node types linked into this target: flow.pass_through, flow.limiter,
// flow.test_delay, test.counter, test.frames, test.collect, and fuzz.views below for repeated and
// joined inputs, choice and list parameters). Plugins named by the input are not loaded: a fuzz
// input must not make the target open shared libraries.

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "graph/graph_spec.hpp"
#include "graph/registry.hpp"
#include "graph/validation.hpp"

namespace {

// A multi-view solver's contract: edges view:0..view:N, joined; a choice and lists.
class FuzzViews : public mocap::graph::Node {
 public:
  static void contract(mocap::graph::Contract& c) {
    c.inputs<mocap::People2D>("view", "one camera", 1, 16);
    c.output<mocap::People2D>("out");
    c.join({{"view"}, mocap::graph::SyncKey::capture_time, 8, 5.0, 100.0});
    c.param_choice("mode", "live", {"live", "full", "off"}, "a choice");
    c.param_list<double>("weights", {1.0}, "a list", {0.0, 10.0});
    c.param_choice_list("joints", {"head"}, {"head", "neck"}, "a list of choices");
  }
  void process(mocap::graph::Context&) override {}
};
MOCAP_REGISTER_NODE("fuzz.views", FuzzViews)

}  // namespace

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
