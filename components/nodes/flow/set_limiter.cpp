// flow.set_limiter: several cameras' frames joined by capture time, passed on as whole sets to a
// stage slower than the cameras (one detector per camera), only while every detector is idle;
// the sets that arrive while any is busy are dropped whole (graph/set_limiter.hpp says why).
// Stream i of `frames` out goes with camera edge i; each frame's header.frame becomes its set's
// number, so the stage's outputs join by frame number (`sync_by: frame`) after it.

#include "graph/set_limiter.hpp"
#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class SetLimiterNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Joins cameras' frames by capture time; passes whole sets while the stage after it "
        "is idle, drops them whole while it is busy (numbered as frames)");
    c.inputs<VideoFrame>("frames", "one camera's frames", 1, 64);
    c.outputs<VideoFrame>("frames", "that camera's frames of the sets passed on", "frames");
    c.join({{"frames"}, SyncKey::capture_time, 64, 10.0, 200.0});
  }

  void process(Context& ctx) override {
    const std::size_t cameras = ctx.input_count("frames");
    bool complete = true, idle = true;
    for (std::size_t i = 0; i < cameras; ++i) {
      complete = complete && ctx.has("frames", i);
      idle = idle && ctx.output_idle("frames", i);
    }
    const std::optional<std::int64_t> number = limiter_.admit(complete, idle);
    for (std::size_t i = 0; i < cameras; ++i) {
      if (!ctx.has("frames", i)) continue;
      if (!number) {
        ctx.count_drop();
        continue;
      }
      VideoFrame frame = ctx.input<VideoFrame>("frames", i);  // shares the pixels
      frame.header.frame = *number;
      ctx.send("frames", i, std::move(frame));
    }
    if (limiter_.counts().sets % 30 == 1) ctx.report_status(limiter_.describe());
  }

  void close(Context& ctx) override { ctx.report_status(limiter_.describe()); }

 private:
  SetLimiter limiter_;
};

MOCAP_REGISTER_NODE("flow.set_limiter", SetLimiterNode)

}  // namespace mocap::nodes
