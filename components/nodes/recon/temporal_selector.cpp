// recon.temporal_selector: picks, per person, one of the matcher's candidates in time and turns it
// into a 3D body in the camera's frame (the state is recon::PeopleSelector). Modes: the paper's
// greedy rule (w previous frames, Lee et al. distance), a Viterbi path with a fixed lag, or the
// nearest candidate alone. With a lag, frame t leaves once frame t + lag has arrived; every input
// frame gives exactly one output frame, in order.

#include <optional>

#include "graph/registry.hpp"
#include "nodes/recon/node_camera.hpp"
#include "posedb/database.hpp"
#include "recon/people_selector.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TemporalSelectorNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Chooses each person's candidate in time and outputs 3D bodies in the camera frame");
    c.input<PoseMatches>("in", "from recon.matcher");
    c.output<People3D>("out", "one message per input frame");
    c.required_param<std::string>("db", "pose database file (the matcher's)");
    c.param<std::string>("mode", "greedy",
                         "greedy (the paper), path (Viterbi with a lag) or nearest");
    c.param<int>("window", 4, "greedy: previous frames compared (w)", {1, 64});
    c.param<bool>("reject_repeat", false, "greedy: never choose the previous frame again");
    c.param<int>("lag", 8, "path: frames of look-ahead before a frame is decided", {0, 1000});
    c.param<double>("data_weight", 50.0, "path: weight of the 2D match distance", {0.0, 1e6});
    c.param<int>("max_missed", 10, "frames a person may be missing before its state is dropped",
                 {0, 10000});
    declare_camera_params(c);
  }

  void open(Context& ctx) override {
    db_.emplace(posedb::Database::open(ctx.param<std::string>("db")));
    bones_.emplace(*db_);
    const std::string mode = ctx.param<std::string>("mode");
    if (mode != "greedy" && mode != "path" && mode != "nearest")
      throw std::invalid_argument("mode must be greedy, path or nearest, not '" + mode + "'");
    recon::PeopleSelectorOptions o;
    o.mode = mode == "path"     ? recon::SelectionMode::path
             : mode == "greedy" ? recon::SelectionMode::greedy
                                : recon::SelectionMode::nearest;
    o.greedy.window = ctx.param<int>("window");
    o.greedy.reject_repeat = ctx.param<bool>("reject_repeat");
    o.path.data_weight = ctx.param<float>("data_weight");
    o.lag = ctx.param<int>("lag");
    o.max_missed = ctx.param<int>("max_missed");
    camera_ = read_camera_params(ctx);
    o.camera = camera_.camera;  // no intrinsics: poses stay as the database cameras see them
    selector_.emplace(*db_, *bones_, std::move(o));
  }

  void process(Context& ctx) override { send(ctx, selector_->push(ctx.input<PoseMatches>("in"))); }

  void close(Context& ctx) override { send(ctx, selector_->finish()); }

 private:
  static void send(Context& ctx, std::vector<People3D> frames) {
    for (People3D& frame : frames) ctx.send("out", std::move(frame));
  }

  std::optional<posedb::Database> db_;
  std::optional<recon::FrameBones> bones_;
  NodeCamera camera_;
  std::optional<recon::PeopleSelector> selector_;
};

MOCAP_REGISTER_NODE("recon.temporal_selector", TemporalSelectorNode)

}  // namespace mocap::nodes
