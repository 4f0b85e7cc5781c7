#pragma once
// multiview.reconstruct's parameters, declared and read in one place (as the detectors' network
// parameters are, nodes/detect/network_params.hpp): what the reconstruction takes (volume, fps,
// report_tentative) and what the skeleton fit takes (fit, lag, bone_frames, window, overlap,
// max_missed, prior_db).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/input_error.hpp"
#include "fit/multiview_people_fitter.hpp"
#include "graph/registry.hpp"
#include "multiview/rig_reconstruction.hpp"
#include "posedb/database.hpp"

namespace mocap::nodes {

inline void declare_reconstruction_params(graph::Contract& c) {
  c.param_list<double>("volume", {},
                       "capture volume xmin,ymin,zmin,xmax,ymax,zmax (world, metres): people "
                       "outside are left out and counted; empty: everywhere");
  c.param<double>("fps", 30.0, "frame rate: tracks predict and expire in seconds", {0.1, 10000.0});
  c.param<bool>("report_tentative", false, "report people from their first frame");
}

inline multiview::ReconstructionOptions read_reconstruction_params(graph::Context& ctx) {
  multiview::ReconstructionOptions options;
  const auto volume = ctx.param<std::vector<double>>("volume");
  if (!volume.empty() && volume.size() != 6)
    throw InputError(
        ctx.node_name() + ".volume",
        "expected 6 numbers (xmin,ymin,zmin,xmax,ymax,zmax), got " + std::to_string(volume.size()));
  if (volume.size() == 6) {
    options.volume_min = glm::vec3(volume[0], volume[1], volume[2]);
    options.volume_max = glm::vec3(volume[3], volume[4], volume[5]);
  }
  options.tracker.fps = ctx.param<double>("fps");
  options.report_tentative = ctx.param<bool>("report_tentative");
  return options;
}

inline void declare_multiview_fit_params(graph::Contract& c) {
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
  c.param<std::string>("prior_db", "",
                       "fit: pose database (CMU train split) whose monocular retrieval is a prior "
                       "of the bones few views see (docs/multiview.md); empty: none");
}

// The fit's options on the rig `solver` reconstructs in (its cameras and floor); nullopt when
// `fit` is off.
inline std::optional<fit::MultiViewPeopleFitOptions> read_multiview_fit_params(
    graph::Context& ctx, const multiview::RigReconstruction& solver) {
  const auto mode = ctx.param<std::string>("fit");
  if (mode == "off") return std::nullopt;
  fit::MultiViewPeopleFitOptions o;
  o.mode = mode == "full" ? fit::StreamFitMode::full : fit::StreamFitMode::live;
  o.fit.cameras = solver.rig().cameras;
  o.fit.fit = fit::multiview_fit_defaults();
  o.fit.fit.ground = solver.floor();
  o.fit.fit.lag = ctx.param<int>("lag");
  o.fit.bone_frames = ctx.param<int>("bone_frames");
  o.window = {ctx.param<int>("window"), ctx.param<int>("overlap")};
  o.max_missed = ctx.param<int>("max_missed");
  // Database::open names the file in its errors, the runtime the node, as for every db param.
  if (const auto db = ctx.param<std::string>("prior_db"); !db.empty())
    o.prior_db = std::make_shared<const posedb::Database>(posedb::Database::open(db));
  return o;
}

}  // namespace mocap::nodes
