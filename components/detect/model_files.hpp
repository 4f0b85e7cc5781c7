#pragma once
// Where the detector models live: a cache outside the repository that tools/setup.sh fills
// (see docs/models.md). A missing model is a clear error that names the setup command.

#include <filesystem>
#include <stdexcept>

namespace mocap::detect {

class ModelMissing : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// $MOCAP_MODEL_DIR, else ${XDG_CACHE_HOME:-$HOME/.cache}/mocap/models: the folder setup.sh uses.
std::filesystem::path model_cache_dir();

// model.json of MoveNet MultiPose in the cache, its weights beside it. Throws ModelMissing.
std::filesystem::path movenet_model_json();

}  // namespace mocap::detect
