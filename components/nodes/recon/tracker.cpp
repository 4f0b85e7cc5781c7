// recon.tracker: stable person ids across frames (recon::Tracker: optimal association with motion
// prediction; ids survive short misses). Keypoints pass through unchanged; only ids are set.

#include "recon/tracker.hpp"
#include "graph/registry.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TrackerNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Assigns stable person ids across frames");
    c.input<People2D>("in");
    c.output<People2D>("out", "the same people with ids (-1: too few joints to track)");
    c.param<int>("max_missed", 10, "frames a person may be missing before the id is retired",
                 {0, 10000});
    c.param<double>("gate", 0.25, "largest association cost (mean joint distance / person size)",
                    {0.01, 10.0});
  }
  void open(Context& ctx) override {
    recon::TrackerOptions options;
    options.max_missed = ctx.param<int>("max_missed");
    options.gate = ctx.param<float>("gate");
    tracker_ = recon::Tracker(options);
  }
  void process(Context& ctx) override {
    People2D out = ctx.input<People2D>("in");
    const KeypointLayout& lay = layout(out.layout);
    people_.resize(out.people.size());
    ids_.resize(out.people.size());
    for (std::size_t p = 0; p < out.people.size(); ++p) {
      to_body15(lay, flatten(out.people[p]), people_[p].joints_xyc);
      people_[p].box = out.people[p].box;
    }
    tracker_.update(people_, ids_);
    for (std::size_t p = 0; p < out.people.size(); ++p) out.people[p].id = ids_[p];
    ctx.send("out", std::move(out));
  }

 private:
  std::span<const float> flatten(const Person2D& person) {
    flat_.clear();
    for (const auto& k : person.joints) flat_.insert(flat_.end(), {k.x, k.y, k.confidence});
    return flat_;
  }
  recon::Tracker tracker_;
  std::vector<recon::PersonKeypoints> people_;
  std::vector<int> ids_;
  std::vector<float> flat_;
};

MOCAP_REGISTER_NODE("recon.tracker", TrackerNode)

}  // namespace mocap::nodes
