// flow.limiter: keeps a slow stage on fresh data in live graphs. Put it in front of the slow node
// with a `latest` edge into the limiter: the limiter then drops frames that are already older
// than max_age_ms (a stall upstream must not be replayed) and caps the rate at max_fps; the
// `latest` edge itself guarantees that the slow node always takes the newest frame.

#include "graph/registry.hpp"
#include "graph/transport.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class FlowLimiter : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Drops messages older than max_age_ms and beyond max_fps (drops are counted)");
    c.input_any("in");
    c.output_same_as("out", "in");
    c.param<double>("max_age_ms", 0.0, "drop messages captured longer ago (0: no limit)",
                    {0, 3.6e6});
    c.param<double>("max_fps", 0.0, "at most this many messages per second (0: no limit)",
                    {0, 1e6});
  }
  void open(Context& ctx) override {
    max_age_ns_ = static_cast<std::int64_t>(ctx.param<double>("max_age_ms") * 1e6);
    const double fps = ctx.param<double>("max_fps");
    min_gap_ns_ = fps > 0 ? static_cast<std::int64_t>(1e9 / fps) : 0;
  }
  void process(Context& ctx) override {
    const std::int64_t now = realtime_ns();
    const bool stale = max_age_ns_ > 0 && now - ctx.header().capture_ns > max_age_ns_;
    const bool too_soon =
        min_gap_ns_ > 0 && last_sent_ns_ != 0 && now - last_sent_ns_ < min_gap_ns_;
    if (stale || too_soon) return ctx.count_drop();
    last_sent_ns_ = now;
    ctx.forward("out", "in");
  }

 private:
  std::int64_t max_age_ns_ = 0, min_gap_ns_ = 0, last_sent_ns_ = 0;
};

MOCAP_REGISTER_NODE("flow.limiter", FlowLimiter)

}  // namespace mocap::nodes
