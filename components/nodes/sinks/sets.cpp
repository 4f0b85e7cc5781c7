// sink.sets: joins its inputs into sets (by capture time by default: several live cameras) and
// keeps nothing. The synchroniser's counts (complete sets, missing per input, skew) are the
// result, printed with the graph's statistics: a capture rig's synchronisation measured without
// a detector (tools/bench/rig_live_bench.cpp), or a quick check of live sources. Its status line
// gives the sets' age when joined (now - the oldest member's capture time, p50/p95 over the last
// 1024 sets): the latency of whatever stage is in front of it.

#include <cstdio>

#include "graph/registry.hpp"
#include "graph/transport.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class SetsSink : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Joins its inputs into sets and discards them; the sets are counted in the statistics");
    c.inputs_any("in", "a stream to join (any type): one per camera", 1, 64);
    // 20 ms, as flow.set_limiter's: 0.6 of a 30 fps period, so free-running cameras join at any
    // phase; a stalled camera holds the others back 200 ms at most.
    // A late message is counted and dropped: passed alone it would count as a set of its own.
    c.join({{"in"}, SyncKey::capture_time, 64, 20.0, 200.0, LateMessages::drop});
  }
  void process(Context& ctx) override {
    std::int64_t oldest = 0;
    for (std::size_t i = 0; i < ctx.input_count("in"); ++i) {
      if (!ctx.has("in", i)) continue;
      const std::int64_t capture = ctx.current("in", i).header().capture_ns;
      if (oldest == 0 || capture < oldest) oldest = capture;
    }
    if (oldest > 0) age_.add(realtime_ns() - oldest);
    if (++sets_ % 30 == 1) report(ctx);
  }
  void close(Context& ctx) override { report(ctx); }

 private:
  void report(Context& ctx) {
    const auto [p50, p95] = age_.percentiles_us();
    char text[96];
    std::snprintf(text, sizeof text, "age when joined p50 %.1f ms p95 %.1f ms", p50 / 1000.0,
                  p95 / 1000.0);
    ctx.report_status(text);
  }

  LatencyWindow age_;
  std::uint64_t sets_ = 0;
};

MOCAP_REGISTER_NODE("sink.sets", SetsSink)

}  // namespace mocap::nodes
