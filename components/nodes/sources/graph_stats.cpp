// graph.stats: the graph's own statistics as a stream (per node: in, out, drops, latency, queue
// depth), e.g. into sink.publish for a dashboard. Runs until the rest of the graph has finished
// and sends a last snapshot then.

#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class GraphStatsSource : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Emits GraphStats snapshots every period_ms while the graph runs, and a final one");
    c.output<GraphStats>("out");
    c.param<double>("period_ms", 1000.0, "time between snapshots", {10, 3.6e6});
    c.runs_until_graph_ends();
  }
  void open(Context& ctx) override {
    period_ =
        std::chrono::nanoseconds(static_cast<std::int64_t>(ctx.param<double>("period_ms") * 1e6));
  }
  void process(Context& ctx) override {
    if (ctx.sleep_for(period_)) emit(ctx);
  }
  void close(Context& ctx) override { emit(ctx); }

 private:
  void emit(Context& ctx) {
    GraphStats stats = ctx.stats();
    stats.header.seq = seq_++;
    ctx.send("out", std::move(stats));
  }
  std::chrono::nanoseconds period_{0};
  std::uint64_t seq_ = 0;
};

MOCAP_REGISTER_NODE("graph.stats", GraphStatsSource)

}  // namespace mocap::nodes
