#include "input_kind.hpp"

#include <filesystem>

#include "core/input_error.hpp"
#include "video/video_source.hpp"

namespace mocap::cli {

InputKind input_kind(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.starts_with(kAravisPrefix)) return InputKind::camera;
  const video::SourceKind source = video::classify(path);
  if (source == video::SourceKind::device || source == video::SourceKind::network)
    return InputKind::camera;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    bool images = false;
    for (const auto& e : fs::directory_iterator(path, ec)) {
      const std::string name = e.path().filename().string();
      if (name.ends_with(".json")) return InputKind::openpose_json;
      images = images || video::is_image_file_name(name);
    }
    if (images) return InputKind::video;
    throw InputError(path,
                     "neither OpenPose JSON files (*.json) nor images (.png, .jpg, ...) here");
  }
  if (source == video::SourceKind::file && !fs::exists(path, ec))
    throw InputError(path, "no such file or folder");
  return InputKind::video;
}

}  // namespace mocap::cli
