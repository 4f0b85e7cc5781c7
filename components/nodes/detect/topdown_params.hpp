#pragma once
// detect.topdown's parameters, declared and read in one place (as network_params.hpp does for every
// detector node), so that the node itself stays an adapter.

#include "detect/topdown_detector.hpp"
#include "graph/registry.hpp"

namespace mocap::nodes {

// Every parameter of detect.topdown, in the order `mocap graph inspect` lists them (the model
// files, pose_model_file and box_model_file, are read by the node when it opens the networks).
void declare_topdown_params(graph::Contract& c);

// The detector's options from those parameters (the network runtime and threads included).
detect::TopDownOptions read_topdown_params(graph::Context& ctx);

}  // namespace mocap::nodes
