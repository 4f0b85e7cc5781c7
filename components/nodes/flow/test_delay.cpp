// test.delay: forwards every message after a pause, playing a slow stage (a 2D detector) in tests.

#include <thread>

#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TestDelay : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Forwards every message after delay_ms of busy time (a slow stage)");
    c.input_any("in");
    c.output_same_as("out", "in");
    c.param<double>("delay_ms", 10.0, "time spent on each message", {0, 60000});
  }
  void open(Context& ctx) override {
    delay_ =
        std::chrono::nanoseconds(static_cast<std::int64_t>(ctx.param<double>("delay_ms") * 1e6));
  }
  void process(Context& ctx) override {
    std::this_thread::sleep_for(delay_);  // counts as processing time, unlike ctx.sleep_for
    ctx.forward("out", "in");
  }

 private:
  std::chrono::nanoseconds delay_{0};
};

MOCAP_REGISTER_NODE("test.delay", TestDelay)

}  // namespace mocap::nodes
