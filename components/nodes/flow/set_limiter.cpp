// flow.set_limiter: several cameras' frames joined by capture time, passed on as whole sets to a
// stage slower than the cameras (one detector per camera), only while every detector is idle;
// the sets that arrive while any is busy are dropped whole, and partial sets unless the cameras
// they lack are away (no frame for sync_wait_ms): graph/set_limiter.hpp says why.
// Stream i of `frames` out goes with camera edge i; each frame's header.frame becomes its set's
// number, so the stage's outputs join by frame number (`sync_by: frame`) after it.

#include <optional>
#include <vector>

#include "graph/registry.hpp"
#include "graph/set_limiter.hpp"

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
    // A frame that comes after its set went on (sync_wait_ms) is dropped, not passed as a set of
    // its own: that set would take a number (shifting the time of every later set) and, alone,
    // keep its camera from counting as away, so that the others' sets would be dropped as partial.
    // 20 ms: 0.6 of a 30 fps period. Free-running cameras' frames are up to half a period apart,
    // so a shorter tolerance splits every instant at an unlucky phase (docs/cameras.md,
    // "Free-running RTSP cameras"); under a period, a set never reaches a camera's next frame.
    c.join({{"frames"}, SyncKey::capture_time, 64, 20.0, 200.0, LateMessages::drop});
  }

  void open(Context& ctx) override {
    const auto stall_ns = static_cast<std::int64_t>(ctx.param<double>("sync_wait_ms") * 1e6);
    limiter_.emplace(ctx.input_count("frames"), stall_ns);
    present_.resize(ctx.input_count("frames"));
  }

  void process(Context& ctx) override {
    const std::size_t cameras = present_.size();
    bool idle = true;
    for (std::size_t i = 0; i < cameras; ++i) {
      present_[i] = ctx.has("frames", i);
      idle = idle && ctx.output_idle("frames", i);
    }
    const std::optional<std::int64_t> number =
        limiter_->admit(present_, ctx.header().capture_ns, idle);
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
    if (limiter_->counts().sets % 30 == 1) ctx.report_status(limiter_->describe());
  }

  void close(Context& ctx) override {
    if (limiter_) ctx.report_status(limiter_->describe());
  }

 private:
  std::optional<SetLimiter> limiter_;
  std::vector<bool> present_;
};

MOCAP_REGISTER_NODE("flow.set_limiter", SetLimiterNode)

}  // namespace mocap::nodes
