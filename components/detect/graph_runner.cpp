#include "detect/graph_runner.hpp"

#include <stdexcept>

#include "detect/model_files.hpp"
#include "detect/runner_backends.hpp"

namespace mocap::detect {

std::size_t GraphTensor::size() const {
  std::size_t n = 1;
  for (const std::int64_t d : shape) n *= static_cast<std::size_t>(d);
  return n;
}

Backend parse_backend(std::string_view name) {
  if (name == "auto") return Backend::automatic;
  if (name == "xnnpack") return Backend::xnnpack;
  if (name == "opencv") return Backend::opencv;
  throw std::invalid_argument("unknown network runtime '" + std::string(name) +
                              "': use auto, xnnpack or opencv");
}

std::string_view backend_name(Backend backend) {
  switch (backend) {
    case Backend::xnnpack:
      return "xnnpack";
    case Backend::opencv:
      return "opencv";
    case Backend::automatic:
      break;
  }
  return "auto";
}

bool xnnpack_available() {
#ifdef MOCAP_HAVE_XNNPACK
  return initialise_xnnpack();
#else
  return false;
#endif
}

Backend resolve_backend(Backend requested) {
  if (requested != Backend::automatic) return requested;
  return xnnpack_available() ? Backend::xnnpack : Backend::opencv;
}

std::unique_ptr<GraphRunner> make_graph_runner(std::shared_ptr<const TfjsModel> model,
                                               std::span<const std::string> outputs,
                                               const RunnerOptions& options) {
  const Backend backend = resolve_backend(options.backend);
  if (backend == Backend::xnnpack) {
#ifdef MOCAP_HAVE_XNNPACK
    if (!initialise_xnnpack())
      throw std::runtime_error("XNNPACK does not run on this processor; use backend opencv");
    try {
      return make_xnnpack_runner(model, outputs, options);
    } catch (const ModelError&) {
      // `auto` falls back to cv::dnn for a model XNNPACK is not given for; asked by name, the
      // error (naming the operations) stands.
      if (options.backend != Backend::automatic) throw;
    }
#else
    throw std::runtime_error(
        "this build has no XNNPACK runtime (Debian package libxnnpack-dev was missing when it "
        "was configured); use backend opencv or auto");
#endif
  }
  return make_opencv_runner(std::move(model), outputs, options);
}

std::unique_ptr<GraphRunner> make_graph_runner(const std::filesystem::path& model_json,
                                               std::span<const std::string> outputs,
                                               const RunnerOptions& options) {
  try {
    return make_graph_runner(std::make_shared<const TfjsModel>(read_tfjs_model(model_json)),
                             outputs, options);
  } catch (const ModelError& e) {
    // A damaged file, or another model's (no such outputs): the user's fix is fetching it again.
    throw ModelError(std::string(e.what()) + "; if the file is damaged or not this model, " +
                     kFetchModelsHint);
  }
}

}  // namespace mocap::detect
