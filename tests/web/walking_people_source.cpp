// unit.walking_people: a source of `count` synthetic people (tests/support/walking_people.hpp)
// at `fps` frames a second, for the viewer's browser test and benchmark; `frames` 0 runs until
// the graph is stopped.

#include "graph/registry.hpp"
#include "support/walking_people.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class WalkingPeopleSource : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Test source: synthetic walking people at a fixed rate");
    c.output<People3D>("out");
    c.param<int>("count", 3, "people per frame", {0, 100});
    c.param<double>("fps", 30.0, "frames a second", {1.0, 1000.0});
    c.param<int>("frames", 0, "frames to send (0: until stopped)", {0, 100000000});
  }
  void open(Context& ctx) override {
    count_ = ctx.param<int>("count");
    fps_ = ctx.param<double>("fps");
    frames_ = ctx.param<int>("frames");
    start_ = std::chrono::steady_clock::now();
  }
  void process(Context& ctx) override {
    if (frames_ > 0 && frame_ >= frames_) return ctx.finish();
    // Paced by the clock, not by sleeps alone, so the rate holds whatever sending costs.
    const auto due = start_ + std::chrono::nanoseconds(static_cast<std::int64_t>(
                                  static_cast<double>(frame_) / fps_ * 1e9));
    const auto wait = due - std::chrono::steady_clock::now();
    if (wait > std::chrono::nanoseconds(0) && !ctx.sleep_for(wait)) return;
    ctx.send("out", test::walking_people(count_, frame_, fps_));
    ++frame_;
  }

 private:
  int count_ = 3, frames_ = 0;
  double fps_ = 30.0;
  std::int64_t frame_ = 0;
  std::chrono::steady_clock::time_point start_;
};

MOCAP_REGISTER_NODE("unit.walking_people", WalkingPeopleSource)

}  // namespace mocap::nodes
