// flow.pass_through: forwards every message unchanged (no copy). Useful to name a point in a
// graph, to move a stream across a process boundary, and as the smallest example of a node.

#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class PassThrough : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Forwards every message unchanged");
    c.input_any("in");
    c.output_same_as("out", "in");
  }
  void process(Context& ctx) override { ctx.forward("out", "in"); }
};

MOCAP_REGISTER_NODE("flow.pass_through", PassThrough)

}  // namespace mocap::nodes
