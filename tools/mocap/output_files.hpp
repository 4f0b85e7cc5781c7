#pragma once
// How `mocap` commands write files: never over one of their inputs, whole or not at all (a
// temporary name renamed into place), and JSON that stays valid whatever bytes a path holds.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace mocap::cli {

// Whether two paths name the same file: through symlinks, `..` and hard links when both exist,
// by their absolute normal form otherwise.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

// One input of a command: what names it on the command line ("--rig", "IN.bvh") and its path.
struct NamedPath {
  std::string label;
  std::string path;
};

// Throws InputError naming both when `output` (given as `output_label`) is one of the inputs.
void refuse_output_over_inputs(const NamedPath& output, const std::vector<NamedPath>& inputs);

// Writes `bytes` to `path` as a whole: into a temporary file beside it, flushed to the disk, then
// renamed over `path`, so that a failure (disk full, a kill) leaves the earlier file or nothing,
// never a cut one. A path that exists and is not a regular file (/dev/null, /dev/stdout) is
// written in place. Throws InputError naming the file.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

// JSON text in which bytes that are not UTF-8 (a path the OS accepts can hold any) are replaced by
// U+FFFD instead of failing: the output stays valid JSON.
std::string json_text(const nlohmann::json& value, int indent = -1);
std::string json_text(const nlohmann::ordered_json& value, int indent = -1);

}  // namespace mocap::cli
