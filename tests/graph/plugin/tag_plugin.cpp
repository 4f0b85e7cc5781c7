// A plugin built by the tests: one node type, plugin.tag, that re-labels the stream of People2D
// messages. It links against nothing; the host program provides the framework.

#include "graph/registry.hpp"

namespace {
using namespace mocap;
using namespace mocap::graph;

class Tag : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Copies People2D messages with the stream id replaced by `stream`");
    c.input<People2D>("in");
    c.output<People2D>("out");
    c.param<std::string>("stream", "tagged", "the new stream id");
  }
  void open(Context& ctx) override { stream_ = ctx.param<std::string>("stream"); }
  void process(Context& ctx) override {
    People2D copy = ctx.input<People2D>("in");
    copy.header.stream = stream_;
    ctx.send("out", std::move(copy));
  }

 private:
  std::string stream_;
};

}  // namespace

MOCAP_REGISTER_NODE("plugin.tag", Tag)
MOCAP_PLUGIN()
