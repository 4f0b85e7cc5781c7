// recon.fit: the kinematic skeleton fitting after the temporal selector (docs/fitting.md; the
// algorithm and the per-person state are fit::PeopleFitter). Each person is fitted with constant
// bone lengths and placed in the camera frame (Person3D::placed, root.translation); the floor, from
// the camera file or the feet, travels on every output once known. One output per input frame, in
// order. live: fixed lag. full: overlapping windows per person, frames leave as their window is
// solved. off: passes the poses on. A stop: no more window solves, a quick one at close().

#include <iostream>
#include <optional>

#include "camera/camera_file.hpp"
#include "fit/people_fitter.hpp"
#include "graph/registry.hpp"
#include "nodes/recon/node_camera.hpp"
#include "posedb/database.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class FitNode : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Fits each person's skeleton to their 2D keypoints (Ceres): constant bone lengths, root "
        "placed in the camera frame, feet on the floor");
    c.input<People3D>("in", "from recon.temporal_selector (poses with their 2D keypoints)");
    c.output<People3D>("out", "one message per input frame; placed people, floor when known");
    c.required_param<std::string>("db", "the pose database the poses come from (foot contact)");
    c.param<std::string>("mode", "live",
                         "live (fixed lag), full (overlapping windows, offline) or off (pass "
                         "through)");
    c.param<int>("lag", 3, "live: frames of look-ahead before a frame is output", {0, 100});
    c.param<int>("iterations", 8, "live: solver iterations per frame", {1, 100});
    c.param<int>("window", 64, "full: frames solved together", {2, 10000});
    c.param<int>("overlap", 16, "full: frames of a window solved again with the next", {1, 9999});
    c.param<int>("max_missed", 10, "frames a person may be missing before their fit ends",
                 {0, 10000});
    declare_camera_params(c);  // a camera file's floor is used too (ground: auto)
    c.param<std::string>("ground", "auto",
                         "auto (the camera file's floor, else estimated from the feet), feet "
                         "(always estimated) or off (no floor)");
    c.param<double>("clearance", 0.07, "ankle joint height over the floor, metres", {0.0, 0.5});
    c.param<bool>("contact", true,
                  "keep feet in contact still (off for walking in place: a treadmill)");
  }

  void open(Context& ctx) override {
    const auto mode = ctx.param<std::string>("mode"), ground = ctx.param<std::string>("ground");
    if (mode != "live" && mode != "full" && mode != "off")
      throw std::invalid_argument("mode must be live, full or off, not '" + mode + "'");
    if (mode == "off") return;
    if (ground != "auto" && ground != "feet" && ground != "off")
      throw std::invalid_argument("ground must be auto, feet or off, not '" + ground + "'");
    fit::PeopleFitOptions o;
    o.mode = mode == "full" ? fit::StreamFitMode::full : fit::StreamFitMode::live;
    o.fit.lag = ctx.param<int>("lag");
    o.fit.live_iterations = ctx.param<int>("iterations");
    o.fit.ankle_clearance_m = ctx.param<double>("clearance");
    o.window = {ctx.param<int>("window"), ctx.param<int>("overlap")};
    o.max_missed = ctx.param<int>("max_missed");
    db_.emplace(posedb::Database::open(ctx.param<std::string>("db")));
    if (ctx.param<bool>("contact")) o.contacts = &contacts_.emplace(*db_);
    camera_ = read_camera_params(ctx);
    if (!camera_.known())
      throw std::invalid_argument(
          "the fitting needs the camera: set 'camera' (a calibration file) or 'image_width' and "
          "'image_height' (with 'hfov_deg')");
    // The fit places people in the camera's frame (its floor is the camera file's, in that frame):
    // the camera file's pose, if any, is not the fit's world.
    o.fit.camera = camera_.camera;
    o.fit.camera.rotation = glm::dmat3(1.0);
    o.fit.camera.translation = glm::dvec3(0.0);
    o.undistort = [this](std::array<Keypoint2D, kBodyJoints>& k) { undistort(camera_, k); };
    o.estimate_ground = ground != "off";
    if (camera_.assumed) {
      std::cerr << "recon.fit '" << ctx.node_name() << "': no camera file, assuming a pinhole of "
                << camera_.hfov_deg << " deg horizontal field of view, principal point at the "
                << "image centre, no distortion\n";
    } else if (ground == "auto") {
      if (const auto p = camera::read_ground_plane(ctx.param<std::string>("camera")))
        o.calibrated_ground = *p;
    }
    fitter_.emplace(std::move(o));
  }

  void process(Context& ctx) override {
    if (!fitter_) return ctx.forward("out", "in");
    if (ctx.stop_requested()) fitter_->stop();  // the drain: no long solve from now on
    send(ctx, fitter_->push(ctx.input<People3D>("in")));
    // The statistics' status column: what is fitted and the time per frame (fit::FrameTimes).
    if (fitter_->frame_times().count() % 30 == 1) ctx.report_status(fitter_->summary());
  }

  void close(Context& ctx) override {
    if (!fitter_) return;
    if (ctx.stop_requested()) fitter_->stop();
    send(ctx, fitter_->finish());
    ctx.report_status(fitter_->summary());
    std::cerr << "recon.fit '" << ctx.node_name() << "': " << fitter_->summary() << "\n";
  }

 private:
  static void send(Context& ctx, std::vector<People3D> frames) {
    for (People3D& frame : frames) ctx.send("out", std::move(frame));
  }

  std::optional<posedb::Database> db_;
  std::optional<fit::ContactDetector> contacts_;
  NodeCamera camera_;
  std::optional<fit::PeopleFitter> fitter_;
};

MOCAP_REGISTER_NODE("recon.fit", FitNode)

}  // namespace mocap::nodes
