// test.fail: forwards messages, then throws on message number `after` (a failing stage in tests).

#include <stdexcept>

#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TestFail : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Forwards messages and fails on message number `after`");
    c.input_any("in");
    c.output_same_as("out", "in");
    c.param<std::int64_t>("after", 10, "messages forwarded before failing", {0, 1e12});
  }
  void open(Context& ctx) override { after_ = ctx.param<std::uint64_t>("after"); }
  void process(Context& ctx) override {
    if (seen_++ == after_)
      throw std::runtime_error("failing on purpose after " + std::to_string(after_) + " messages");
    ctx.forward("out", "in");
  }

 private:
  std::uint64_t after_ = 0, seen_ = 0;
};

MOCAP_REGISTER_NODE("test.fail", TestFail)

}  // namespace mocap::nodes
