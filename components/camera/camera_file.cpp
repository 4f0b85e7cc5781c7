#include "camera/camera_file.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <glm/matrix.hpp>
#include <opencv2/core.hpp>

#include "camera/rig_file.hpp"
#include "core/input_error.hpp"
#include "core/messages.hpp"

namespace mocap::camera {
namespace {

Rig read_one_camera_rig(const std::string& path) {
  Rig rig = read_rig(path);
  if (rig.cameras.size() != 1)
    throw InputError(path, "is a rig of " + std::to_string(rig.cameras.size()) +
                               " cameras; one camera is needed here");
  return rig;
}

// The single-camera file's avg_reprojection_error (-1 when absent), and whether `text` is that
// file (no `cameras` list).
struct SingleCameraFile {
  bool single = false;
  double rms_px = -1.0;
};
SingleCameraFile single_camera_file(const std::string& text, const std::string& path) {
  SingleCameraFile out;
  try {
    cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY);
    out.single = fs["cameras"].empty();
    const cv::FileNode rms = fs["avg_reprojection_error"];
    if (rms.isReal() || rms.isInt()) out.rms_px = static_cast<double>(rms);
    if (!std::isfinite(out.rms_px) || out.rms_px < 0) out.rms_px = -1.0;
  } catch (const cv::Exception& e) {
    throw InputError(path, "not a readable OpenCV YAML file (" + e.err + ")");
  }
  return out;
}

}  // namespace

Camera read_camera_file(const std::string& path) {
  return std::move(read_one_camera_rig(path).cameras.front());
}

std::optional<GroundPlane> read_ground_plane(const std::string& path) {
  return read_one_camera_rig(path).floor_in_camera(0);
}

void write_camera_file(const std::string& path, const Camera& camera, double rms_px,
                       const std::optional<GroundPlane>& ground) {
  // The file keeps no name (it reads as kDefaultCamera): a camera without one is fine.
  Camera named = camera;
  if (named.name.empty()) named.name = std::string(kDefaultCamera);
  if (const std::string p = camera_problem(named); !p.empty())
    throw std::invalid_argument("write_camera_file: the camera " + p);
  if (ground)
    if (const std::string p = ground_problem(*ground); !p.empty())
      throw std::invalid_argument("write_camera_file: the ground plane's " + p);
  try {
    cv::FileStorage fs(path, cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
    if (!fs.isOpened()) throw InputError(path, "cannot write");
    fs << "image_width" << camera.width;
    fs << "image_height" << camera.height;
    const std::array<double, 9> k = camera.matrix();
    fs << "camera_matrix" << cv::Mat(3, 3, CV_64F, const_cast<double*>(k.data()));
    // An empty distortion is written as zeros, since OpenCV cannot store an empty matrix.
    std::vector<double> d = camera.distortion;
    if (d.empty()) d.assign(camera.fisheye ? 4 : 5, 0.0);
    fs << "distortion_coefficients" << cv::Mat(1, static_cast<int>(d.size()), CV_64F, d.data());
    if (camera.fisheye) fs << "fisheye" << 1;
    if (rms_px >= 0) fs << "avg_reprojection_error" << rms_px;
    if (ground) {
      fs << "ground_normal"
         << (cv::Mat_<double>(3, 1) << ground->normal.x, ground->normal.y, ground->normal.z);
      fs << "ground_offset" << ground->offset;
    }
    fs.release();
  } catch (const cv::Exception& e) {
    throw InputError(path, "cannot write (" + e.err + ")");
  }
}

void write_ground_plane(const std::string& path, const GroundPlane& plane) {
  if (const std::string p = ground_problem(plane); !p.empty())
    throw std::invalid_argument("write_ground_plane: the plane's " + p);
  Rig rig = read_one_camera_rig(path);
  const Camera& camera = rig.cameras.front();
  const bool toml = std::filesystem::path(path).extension() == ".toml";
  const SingleCameraFile file =
      toml ? SingleCameraFile{} : single_camera_file(read_rig_text(path), path);
  // Written beside the file, then renamed over it: a failed write leaves the old file intact.
  const std::string temporary = path + ".tmp";
  if (file.single) {
    write_camera_file(temporary, camera, file.rms_px, plane);
  } else {
    // The plane from the camera's frame into the world: x_w = Rᵀ x_c - Rᵀ t.
    const glm::dmat3 to_world = glm::transpose(camera.rotation);
    rig.floor = transformed(plane, to_world, -(to_world * camera.translation));
    write_rig(path, rig);
    return;
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw InputError(path, "cannot replace the file");
  }
}

}  // namespace mocap::camera
