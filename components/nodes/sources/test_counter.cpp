// test.counter: a source of numbered People2D messages with keypoints computed from the sequence
// number, so any stage can check what it got. Used by tests, examples and the benchmark.

#include <cmath>

#include "graph/registry.hpp"
#include "graph/transport.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TestCounter : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Emits `count` numbered People2D messages (COCO-17 keypoints computed from seq)");
    c.output<People2D>("out");
    c.param<std::int64_t>("count", 100, "how many messages before end of stream (0: until stopped)",
                          {0, 1e12});
    c.param<double>("interval_ms", 0.0, "pause between messages", {0, 60000});
    c.param<std::int64_t>("people", 1, "people per message", {0, 64});
    c.param<std::string>("stream", "counter", "stream id written into every header");
  }

  void open(Context& ctx) override {
    count_ = ctx.param<std::uint64_t>("count");
    interval_ =
        std::chrono::nanoseconds(static_cast<std::int64_t>(ctx.param<double>("interval_ms") * 1e6));
    people_ = ctx.param<int>("people");
    stream_ = ctx.param<std::string>("stream");
  }

  void process(Context& ctx) override {
    if (count_ != 0 && seq_ >= count_) return ctx.finish();
    if (seq_ > 0 && interval_.count() > 0 && !ctx.sleep_for(interval_)) return;
    People2D message;
    message.header = {stream_, seq_, realtime_ns(), static_cast<std::int64_t>(seq_)};
    message.layout = LayoutId::coco17;
    for (int p = 0; p < people_; ++p) message.people.push_back(person(p));
    ctx.send("out", std::move(message));
    ++seq_;
  }

 private:
  Person2D person(int index) const {
    Person2D person;
    person.id = index;
    for (int j = 0; j < 17; ++j) {
      const float x = static_cast<float>(seq_ % 1000) + 0.5f * static_cast<float>(j);
      person.joints.push_back(
          {x, static_cast<float>(10 * index + j), 1.0f - 0.01f * static_cast<float>(j)});
    }
    person.box = {0, 0, 100, 200};
    return person;
  }

  std::uint64_t count_ = 0, seq_ = 0;
  std::chrono::nanoseconds interval_{0};
  int people_ = 1;
  std::string stream_;
};

MOCAP_REGISTER_NODE("test.counter", TestCounter)

}  // namespace mocap::nodes
