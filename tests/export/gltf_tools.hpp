#pragma once
// Other programs reading our GLB files in the tests: the Khronos glTF validator (npm
// gltf-validator, run by node from the npm cache of tools/setup.sh) and headless Blender's
// importers. Each returns null (with the reason in `log`) when the program cannot run.

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

namespace mocap::test {

// ${MOCAP_NPM_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/mocap/npm}/node_modules, as tools/setup.sh.
inline std::filesystem::path npm_modules() {
  if (const char* dir = std::getenv("MOCAP_NPM_DIR"); dir && *dir)
    return std::filesystem::path(dir) / "node_modules";
  std::filesystem::path cache;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    cache = xdg;
  } else if (const char* home = std::getenv("HOME"); home && *home) {
    cache = std::filesystem::path(home) / ".cache";
  }
  return cache / "mocap" / "npm" / "node_modules";
}

inline bool on_path(const std::string& program) {
  return std::system(("command -v " + program + " > /dev/null 2>&1").c_str()) == 0;
}

// Why the validator cannot run, or empty when it can.
inline std::string validator_missing() {
  if (!on_path("node")) return "node is not on PATH (Debian: apt-get install nodejs)";
  if (!std::filesystem::exists(npm_modules() / "gltf-validator" / "package.json"))
    return "gltf-validator is not in " + npm_modules().string() + " (tools/setup.sh installs it)";
  return {};
}

// Runs `command`, returns its output and the JSON after the first line starting with `tag`.
inline nlohmann::json tagged_json(const std::string& command, const std::string& tag,
                                  std::string& log) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen((command + " 2>&1").c_str(), "r"), pclose);
  if (!pipe) return nullptr;
  std::array<char, 4096> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe.get())) log += buffer.data();
  const auto at = log.find(tag + " ");
  if (at == std::string::npos) return nullptr;
  const auto begin = at + tag.size() + 1;
  return nlohmann::json::parse(log.substr(begin, log.find('\n', begin) - begin), nullptr, false);
}

// The validator's report of one file: errors, warnings, infos, hints, messages.
inline nlohmann::json validate_gltf(const std::string& path, std::string& log) {
  return tagged_json("node " + std::string(MOCAP_GLTF_VALIDATOR_SCRIPT) + " " +
                         npm_modules().string() + " " + path,
                     "MOCAP_GLTF_VALIDATOR", log);
}

// Blender's BVH and glTF importers on a BVH and the GLB made from it: {"bvh": {...}, "glb": {...}}
// with bones, keyed_frames, keys_per_curve, armatures, meshes.
inline nlohmann::json blender_import_both(const std::string& bvh, const std::string& glb,
                                          std::string& log) {
  return tagged_json("timeout 300 blender --background --factory-startup --python " +
                         std::string(MOCAP_BLENDER_GLTF_SCRIPT) + " -- " + bvh + " " + glb,
                     "MOCAP_BLENDER", log);
}

}  // namespace mocap::test
