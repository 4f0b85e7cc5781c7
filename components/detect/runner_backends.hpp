#pragma once
// Internal to mocap_detect: the two GraphRunner implementations behind make_graph_runner.

#include <memory>
#include <span>
#include <string>

#include "detect/graph_runner.hpp"
#include "detect/tfjs_model.hpp"

namespace mocap::detect {

std::unique_ptr<GraphRunner> make_opencv_runner(std::shared_ptr<const TfjsModel> model,
                                                std::span<const std::string> outputs,
                                                const RunnerOptions& options);

#ifdef MOCAP_HAVE_XNNPACK
// Initialises XNNPACK once per process; false when the processor cannot run it.
bool initialise_xnnpack();
// Throws ModelError naming every operation XNNPACK is not given for, before building anything.
std::unique_ptr<GraphRunner> make_xnnpack_runner(std::shared_ptr<const TfjsModel> model,
                                                 std::span<const std::string> outputs,
                                                 const RunnerOptions& options);
#endif

}  // namespace mocap::detect
