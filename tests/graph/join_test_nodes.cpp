// Node types for the tests of joined inputs (join_test.cpp, harness_test.cpp).
//   unit.pair:   inputs a and b (any type) joined; per set one People2D with a person per input
//                present (id 0 for a, 1 for b) and the header of the set's first message.
//   unit.views:  a repeated People2D input view:0..N joined; per set one People2D whose stream
//                names the views present ("cam0+cam2") and whose people are theirs.
//   unit.window: holds `size` messages, then sends them all (as a windowed offline fit does).

#include <deque>

#include "graph/registry.hpp"

namespace mocap::graph {
namespace {

class Pair : public Node {
 public:
  static void contract(Contract& c) {
    c.input_any("a");
    c.input_any("b");
    c.output<People2D>("out");
    c.join({{"a", "b"}, SyncKey::frame, 64});
  }
  void process(Context& ctx) override {
    People2D out;
    out.header = ctx.header();
    if (ctx.has("a")) out.people.push_back(Person2D{0, {}, {}});
    if (ctx.has("b")) out.people.push_back(Person2D{1, {}, {}});
    ctx.send("out", std::move(out));
  }
};
MOCAP_REGISTER_NODE("unit.pair", Pair)

class Views : public Node {
 public:
  static void contract(Contract& c) {
    c.inputs<People2D>("view", "one camera's people", 1, 8);
    c.output<People2D>("out");
    c.join({{"view"}, SyncKey::frame, 64});
  }
  void process(Context& ctx) override {
    People2D out;
    out.header = ctx.header();
    out.header.stream.clear();
    for (std::size_t i = 0; i < ctx.input_count("view"); ++i) {
      if (!ctx.has("view", i)) continue;
      const People2D& view = ctx.input<People2D>("view", i);
      out.header.stream += (out.header.stream.empty() ? "" : "+") + view.header.stream;
      out.people.insert(out.people.end(), view.people.begin(), view.people.end());
    }
    ctx.send("out", std::move(out));
  }
};
MOCAP_REGISTER_NODE("unit.views", Views)

class Window : public Node {
 public:
  static void contract(Contract& c) {
    c.input_any("in");
    c.output_same_as("out", "in");
    c.param<std::int64_t>("size", 100, "messages held before they all go", {1, 100000});
  }
  void open(Context& ctx) override { size_ = ctx.param<std::size_t>("size"); }
  void process(Context& ctx) override {
    held_.push_back(ctx.current("in"));
    if (held_.size() >= size_) release(ctx);
  }
  void close(Context& ctx) override { release(ctx); }

 private:
  void release(Context& ctx) {
    for (Packet& packet : held_) ctx.send_packet("out", std::move(packet));
    held_.clear();
  }
  std::size_t size_ = 100;
  std::deque<Packet> held_;
};
MOCAP_REGISTER_NODE("unit.window", Window)

}  // namespace
}  // namespace mocap::graph
