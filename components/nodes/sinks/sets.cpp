// sink.sets: joins its inputs into sets (by capture time by default: several live cameras) and
// keeps nothing. The synchroniser's counts (complete sets, missing per input, skew) are the
// result, printed with the graph's statistics: a capture rig's synchronisation measured without
// a detector (tools/bench/rig_live_bench.cpp), or a quick check of live sources.

#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class SetsSink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Joins its inputs into sets and discards them; the sets are counted in the statistics");
    c.inputs_any("in", "a stream to join (any type): one per camera", 1, 64);
    // 30 fps: a third of a frame period; a stalled camera holds the others back 200 ms at most.
    c.join({{"in"}, SyncKey::capture_time, 64, 10.0, 200.0});
  }
  void process(Context&) override {}
};

MOCAP_REGISTER_NODE("sink.sets", SetsSink)

}  // namespace mocap::nodes
