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

std::filesystem::path cached_model_json(std::string_view name) {
  const auto dir = model_cache_dir() / name;
  const std::string stem(name);
  const auto json = dir / (stem + ".json");
  if (!std::filesystem::is_regular_file(json) ||
      !std::filesystem::is_regular_file(dir / (stem + ".bin"))) {
    throw ModelMissing("model " + stem + " not found in " + dir.string() + "; " + kFetchModelsHint);
  }
  return json;
}

std::filesystem::path movenet_model_json() { return cached_model_json("movenet-multipose"); }

}  // namespace mocap::detect
