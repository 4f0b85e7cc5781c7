#include "camera/rig_file.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <stdexcept>
#include <system_error>

#include "core/input_error.hpp"

namespace mocap::camera {
namespace {

// A rig of many cameras is a few hundred bytes per camera; anything beyond is not one.
constexpr std::uintmax_t kMaxRigFileBytes = 1u << 20;

std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool yaml_extension(const std::string& ext) {
  return ext == ".yml" || ext == ".yaml" || ext == ".xml" || ext == ".json";
}

// TOML when the first line that is not blank or a comment opens a [table].
bool looks_like_toml(std::string_view text) {
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view line = text.substr(at, end - at);
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string_view::npos && line[first] != '#') return line[first] == '[';
    at = end + 1;
  }
  return false;
}

}  // namespace

RigFormat rig_format_for_writing(const std::filesystem::path& file) {
  const std::string ext = lower_extension(file);
  if (ext == ".toml") return RigFormat::toml;
  if (ext == ".yml" || ext == ".yaml") return RigFormat::yaml;
  throw InputError(file.string(),
                   "cannot tell the rig format by the extension: use .toml (Pose2Sim/anipose) or "
                   ".yml (OpenCV YAML)");
}

std::string read_rig_text(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(name, "no such file");
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(name, "cannot be read: " + ec.message());
  if (size == 0) throw InputError(name, "empty file");
  if (size > kMaxRigFileBytes)
    throw InputError(name, "too large for a rig or camera file (" + std::to_string(size) +
                               " bytes, at most " + std::to_string(kMaxRigFileBytes) + ")");
  std::ifstream in(file, std::ios::binary);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), static_cast<std::streamsize>(text.size())))
    throw InputError(name, "read error");
  return text;
}

Rig read_rig(const std::filesystem::path& file) {
  const std::string text = read_rig_text(file);
  const std::string ext = lower_extension(file);
  const bool toml = ext == ".toml" || (!yaml_extension(ext) && looks_like_toml(text));
  return toml ? parse_rig_toml(text, file.string()) : parse_rig_yaml(text, file.string());
}

void write_rig(const std::filesystem::path& file, const Rig& rig) {
  if (const std::string p = rig_problem(rig); !p.empty())
    throw std::invalid_argument("write_rig: " + p);
  const std::string text =
      rig_format_for_writing(file) == RigFormat::toml ? format_rig_toml(rig) : format_rig_yaml(rig);
  // Written beside the file, then renamed over it: a failed write leaves no half file.
  std::filesystem::path temporary = file;
  temporary += ".part";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(file.string(), "cannot be written (" + temporary.string() + ")");
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(temporary, ec);
      throw InputError(file.string(), "write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, file, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw InputError(file.string(), "cannot replace the file: " + ec.message());
  }
}

}  // namespace mocap::camera
