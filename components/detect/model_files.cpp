#include "detect/model_files.hpp"

#include <cstdlib>

namespace mocap::detect {
namespace {

std::filesystem::path env_path(const char* name) {
  const char* value = std::getenv(name);
  return value && *value ? std::filesystem::path(value) : std::filesystem::path();
}

}  // namespace

std::filesystem::path model_cache_dir() {
  if (auto dir = env_path("MOCAP_MODEL_DIR"); !dir.empty()) return dir;
  auto cache = env_path("XDG_CACHE_HOME");
  if (cache.empty()) cache = env_path("HOME") / ".cache";
  return cache / "mocap" / "models";
}

std::filesystem::path movenet_model_json() {
  const auto dir = model_cache_dir() / "movenet-multipose";
  const auto json = dir / "movenet-multipose.json";
  if (!std::filesystem::is_regular_file(json) ||
      !std::filesystem::is_regular_file(dir / "movenet-multipose.bin")) {
    throw ModelMissing("MoveNet MultiPose model not found in " + dir.string() +
                       "; run tools/setup.sh --models-only to fetch it (or set MOCAP_MODEL_DIR)");
  }
  return json;
}

}  // namespace mocap::detect
