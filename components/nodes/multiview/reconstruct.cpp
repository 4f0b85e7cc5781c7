// multiview.reconstruct: several calibrated views of one scene, joined by frame (files) or by
// capture time (live cameras: the graph sets sync_by, sync_tolerance_ms, sync_wait_ms), to the
// people in the rig's world (multiview/rig_reconstruction.hpp: undistortion, association,
// triangulation, tracking). People seen by one view only are dropped and counted.

#include <iostream>
#include <memory>
#include <vector>

#include "camera/rig_file.hpp"
#include "core/input_error.hpp"
#include "graph/registry.hpp"
#include "multiview/rig_reconstruction.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class MultiViewReconstructNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Reconstructs the people seen by several calibrated cameras, in the rig's world");
    c.inputs<People2D>("view", "one camera's people (its `camera` names it as the rig does)", 1,
                       multiview::kMaxViews);
    c.output<People3D>("out", "people in the rig's world: track ids, 15 joints in metres");
    c.join({{"view"}, SyncKey::frame, 64});
    c.required_param<std::string>("rig", "rig file: Pose2Sim/anipose TOML or OpenCV YAML");
    c.param_list<double>("volume", {},
                         "capture volume xmin,ymin,zmin,xmax,ymax,zmax (world, metres): people "
                         "outside are left out and counted; empty: everywhere");
    c.param<double>("fps", 30.0, "frame rate: tracks predict and expire in seconds",
                    {0.1, 10000.0});
    c.param<bool>("report_tentative", false, "report people from their first frame");
  }

  void open(Context& ctx) override {
    const std::string file = ctx.param<std::string>("rig");
    multiview::ReconstructionOptions options;
    const auto volume = ctx.param<std::vector<double>>("volume");
    if (!volume.empty() && volume.size() != 6)
      throw InputError(ctx.node_name() + ".volume",
                       "expected 6 numbers (xmin,ymin,zmin,xmax,ymax,zmax), got " +
                           std::to_string(volume.size()));
    if (volume.size() == 6) {
      options.volume_min = glm::vec3(volume[0], volume[1], volume[2]);
      options.volume_max = glm::vec3(volume[3], volume[4], volume[5]);
    }
    options.tracker.fps = ctx.param<double>("fps");
    options.report_tentative = ctx.param<bool>("report_tentative");
    // Live cameras' frame counters are unrelated: the sets are numbered here instead.
    number_sets_ = ctx.param<std::string>("sync_by") == "capture_time";
    solver_ = std::make_unique<multiview::RigReconstruction>(camera::read_rig(file), file, options);
    views_.resize(ctx.input_count("view"));
    if (views_.size() > solver_->rig().cameras.size())
      throw InputError(file, std::to_string(views_.size()) + " views but " +
                                 std::to_string(solver_->rig().cameras.size()) +
                                 " cameras in the rig: one view per camera");
  }

  void process(Context& ctx) override {
    const Header* header = nullptr;
    for (std::size_t i = 0; i < views_.size(); ++i) {
      views_[i] = ctx.has("view", i) ? &ctx.input<People2D>("view", i) : nullptr;
      if (views_[i] && !header) header = &views_[i]->header;
    }
    if (!header) return;
    People3D out;
    out.header = *header;
    out.header.stream = ctx.node_name();
    if (number_sets_) {
      out.header.seq = sets_;
      out.header.frame = static_cast<std::int64_t>(sets_++);
    }
    solver_->solve(views_, out.header.frame, out);
    ctx.send("out", std::move(out));
    if (solver_->counts().sets % 30 == 1)
      ctx.report_status(solver_->counts().describe(solver_->rig()));
  }

  void close(Context& ctx) override {
    if (!solver_) return;
    ctx.report_status(solver_->counts().describe(solver_->rig()));
    std::cerr << ctx.node_name() << ": " << solver_->counts().describe(solver_->rig()) << "\n";
  }

 private:
  std::unique_ptr<multiview::RigReconstruction> solver_;
  std::vector<const People2D*> views_;
  bool number_sets_ = false;
  std::uint64_t sets_ = 0;
};

MOCAP_REGISTER_NODE("multiview.reconstruct", MultiViewReconstructNode)

}  // namespace mocap::nodes
