#pragma once
// The parameters every detector node takes for its networks, declared and read in one place:
// the runtime (`backend`), its `threads`, and a model file given by path or taken from the cache
// tools/setup.sh fills.

#include <filesystem>
#include <string>
#include <string_view>

#include "detect/graph_runner.hpp"
#include "detect/model_files.hpp"
#include "graph/registry.hpp"

namespace mocap::nodes {

// Declares `backend` and `threads`; `threads_zero` says what 0 means for this node.
inline void declare_network_params(graph::Contract& c, const std::string& threads_zero) {
  c.param<std::string>("backend", "auto",
                       "network runtime: auto (XNNPACK when built in, else cv::dnn), xnnpack, "
                       "opencv");
  c.param<int>("threads", 0,
               "network threads (0: " + threads_zero +
                   "); cv::dnn's setting is "
                   "process-wide",
               {0, 64});
}

struct NetworkParams {
  detect::Backend backend = detect::Backend::automatic;
  int threads = 0;
};

inline NetworkParams read_network_params(graph::Context& ctx) {
  return {detect::parse_backend(ctx.param<std::string>("backend")), ctx.param<int>("threads")};
}

// The model.json of parameter `param`: its value when given (it must exist), else `cached` in the
// cache. Throws detect::ModelMissing naming the file and the command that fetches the models.
inline std::filesystem::path model_file(graph::Context& ctx, const std::string& param,
                                        std::string_view cached) {
  const std::string given = ctx.param<std::string>(param);
  if (given.empty()) return detect::cached_model_json(cached);
  if (!std::filesystem::is_regular_file(given))
    throw detect::ModelMissing("model file " + given + " (parameter `" + param + "`) not found; " +
                               detect::kFetchModelsHint + ", or leave it empty");
  return given;
}

}  // namespace mocap::nodes
