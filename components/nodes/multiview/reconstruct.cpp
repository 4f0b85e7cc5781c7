// multiview.reconstruct: several calibrated views of one scene, joined by frame (files) or by
// capture time (live cameras: the graph sets sync_by, sync_tolerance_ms, sync_wait_ms), to the
// people in the rig's world (multiview/rig_reconstruction.hpp: undistortion, association,
// triangulation, tracking). People seen by one view only are dropped and counted. `fit`: each
// track's skeleton fitted on all views (fit::MultiViewPeopleFitter: constant bones, live = fixed
// lag, full = windows), one output per input set, in order.

#include <iostream>
#include <memory>
#include <optional>
#include <vector>

#include "camera/rig_file.hpp"
#include "core/input_error.hpp"
#include "fit/multiview_people_fitter.hpp"
#include "graph/registry.hpp"
#include "multiview/rig_reconstruction.hpp"
#include "nodes/multiview/reconstruct_params.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class MultiViewReconstructNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc("Reconstructs the people seen by several calibrated cameras, in the rig's world");
    c.inputs<People2D>("view", "one camera's people (its `camera` names it as the rig does)", 1,
                       multiview::kMaxViews);
    c.output<People3D>("out", "people in the rig's world: track ids, 15 joints in metres");
    // One output per set: a view that comes after its set went on (sync_wait_ms) is counted and
    // dropped, not solved alone as a second set of the same frame.
    c.join({{"view"}, SyncKey::frame, 64, 0.0, 0.0, LateMessages::drop});
    c.required_param<std::string>("rig", "rig file: Pose2Sim/anipose TOML or OpenCV YAML");
    declare_reconstruction_params(c);  // volume, fps, report_tentative
    declare_multiview_fit_params(c);   // fit, lag, bone_frames, window, overlap, max_missed,
                                       // prior_db
  }

  void open(Context& ctx) override {
    const std::string file = ctx.param<std::string>("rig");
    const multiview::ReconstructionOptions options = read_reconstruction_params(ctx);
    // Live cameras' frame counters are unrelated: the sets are numbered here instead.
    number_sets_ = ctx.param<std::string>("sync_by") == "capture_time";
    solver_ = std::make_unique<multiview::RigReconstruction>(camera::read_rig(file), file, options);
    if (auto fit = read_multiview_fit_params(ctx, *solver_)) fitter_.emplace(std::move(*fit));
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
  bool number_sets_ = false;
  std::uint64_t sets_ = 0;
};

MOCAP_REGISTER_NODE("multiview.reconstruct", MultiViewReconstructNode)

}  // namespace mocap::nodes
