// multiview.reconstruct: several calibrated views of one scene, joined by frame, to the people in
// the rig's world (multiview/rig_reconstruction.hpp: undistortion, association, triangulation,
// tracking). People seen by one view only are dropped and counted. `fit`: each track's skeleton
// fitted on all views (fit::MultiViewPeopleFitter: constant bones, live = fixed lag, full =
// windows), one output per input set, in order.

#include <iostream>
#include <memory>
#include <optional>
#include <vector>

#include "camera/rig_file.hpp"
#include "core/input_error.hpp"
#include "fit/multiview_people_fitter.hpp"
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
    c.param_choice("fit", "off", {"off", "live", "full"},
                   "skeleton fit on all views: off (triangulated joints), live (fixed lag; a new "
                   "person's first bone_frames frames held) or full (windows, offline)");
    c.param<int>("lag", 3, "live fit: frames of look-ahead before a frame is output", {0, 100});
    c.param<int>("bone_frames", 30, "live fit: a new person's frames that give the bone lengths",
                 {1, 10000});
    c.param<int>("window", 300, "full fit: frames solved together", {2, 100000});
    c.param<int>("overlap", 30, "full fit: frames of a window solved again with the next",
                 {0, 99999});
    c.param<int>("max_missed", 10, "fit: frames a person may be missing before their fit ends",
                 {0, 10000});
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
    solver_ = std::make_unique<multiview::RigReconstruction>(camera::read_rig(file), file, options);
    if (const auto mode = ctx.param<std::string>("fit"); mode != "off") {
      fit::MultiViewPeopleFitOptions o;
      o.mode = mode == "full" ? fit::StreamFitMode::full : fit::StreamFitMode::live;
      o.fit.cameras = solver_->rig().cameras;
      o.fit.fit = fit::multiview_fit_defaults();
      o.fit.fit.ground = solver_->floor();
      o.fit.fit.lag = ctx.param<int>("lag");
      o.fit.bone_frames = ctx.param<int>("bone_frames");
      o.window = {ctx.param<int>("window"), ctx.param<int>("overlap")};
      o.max_missed = ctx.param<int>("max_missed");
      fitter_.emplace(std::move(o));
    }
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
    solver_->solve(views_, header->frame, out);
    if (!fitter_) {
      ctx.send("out", std::move(out));
    } else {
      if (ctx.stop_requested()) fitter_->stop();  // the drain: no long solve from now on
      const multiview::FrameResult* result = solver_->last_result();
      send(ctx, result ? fitter_->push(solver_->observations(), *result, solver_->keypoint_set(),
                                       std::move(out))
                       : fitter_->push(std::move(out)));
    }
    if (solver_->counts().sets % 30 == 1)
      ctx.report_status(solver_->counts().describe(solver_->rig()));
  }

  void close(Context& ctx) override {
    if (!solver_) return;
    std::string status = solver_->counts().describe(solver_->rig());
    if (fitter_) {
      if (ctx.stop_requested()) fitter_->stop();
      send(ctx, fitter_->finish());
      status += "; " + fitter_->summary();
    }
    ctx.report_status(status);
    std::cerr << ctx.node_name() << ": " << status << "\n";
  }

 private:
  static void send(Context& ctx, std::vector<People3D> frames) {
    for (People3D& frame : frames) ctx.send("out", std::move(frame));
  }

  std::unique_ptr<multiview::RigReconstruction> solver_;
  std::optional<fit::MultiViewPeopleFitter> fitter_;
  std::vector<const People2D*> views_;
};

MOCAP_REGISTER_NODE("multiview.reconstruct", MultiViewReconstructNode)

}  // namespace mocap::nodes
