#pragma once
// Where the detector models live: a cache outside the repository that tools/setup.sh fills
// (see docs/models.md). A missing model is a clear error that names the setup command.

#include <filesystem>
#include <stdexcept>
#include <string_view>

namespace mocap::detect {

class ModelMissing : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// $MOCAP_MODEL_DIR, else ${XDG_CACHE_HOME:-$HOME/.cache}/mocap/models: the folder setup.sh uses.
std::filesystem::path model_cache_dir();

// <cache>/<name>/<name>.json of a model tools/setup.sh fetches (movenet-multipose,
// movenet-lightning, movenet-thunder, centernet, nanodet), its weights beside it. Throws
// ModelMissing naming the folder and the command that fetches it.
std::filesystem::path cached_model_json(std::string_view name);

// model.json of MoveNet MultiPose in the cache, its weights beside it. Throws ModelMissing.
std::filesystem::path movenet_model_json();

// What to tell a user whose model file is missing or wrong: the command that fetches the models.
inline constexpr const char* kFetchModelsHint =
    "run tools/setup.sh --models-only to fetch the models into the cache (or set MOCAP_MODEL_DIR)";

}  // namespace mocap::detect
