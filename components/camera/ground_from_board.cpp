#include "camera/ground_from_board.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "camera/board_detection.hpp"
#include "core/input_error.hpp"

namespace mocap::camera {

FloorFromBoard ground_from_board_image(const std::string& image, const Camera& camera,
                                       const BoardSpec& board, double board_thickness_mm) {
  check_board(board);
  if (!(board_thickness_mm >= 0 && std::isfinite(board_thickness_mm)))
    throw std::invalid_argument("ground from board: thickness must be finite and >= 0");
  if (camera.fisheye)
    throw std::invalid_argument("ground from board: a fisheye camera is not supported");
  cv::Mat picture;
  try {
    picture = cv::imread(image, cv::IMREAD_COLOR);
  } catch (const cv::Exception&) {
    picture = cv::Mat();
  }
  if (picture.empty()) throw InputError(image, "unreadable image");
  if (picture.cols != camera.width || picture.rows != camera.height)
    throw InputError(image, "the image is " + std::to_string(picture.cols) + "x" +
                                std::to_string(picture.rows) + ", the camera file is for " +
                                std::to_string(camera.width) + "x" + std::to_string(camera.height));
  cv::Mat K(3, 3, CV_64F);
  const std::array<double, 9> k = camera.matrix();
  for (int i = 0; i < 9; ++i) K.at<double>(i / 3, i % 3) = k[static_cast<std::size_t>(i)];
  cv::Mat D = cv::Mat::zeros(1, 5, CV_64F);
  if (!camera.distortion.empty()) D = cv::Mat(camera.distortion, true).reshape(1, 1);

  const detail::BoardDetection found =
      detail::detect_board(detail::to_gray(picture), board, 6, K, D);
  if (!found.found()) throw InputError(image, found.reason + " (" + describe(board) + ")");
  const auto& object = found.corners.object;
  const auto& pixels = found.corners.image;

  cv::Mat rvec, tvec;
  cv::solvePnP(object, pixels, K, D, rvec, tvec, false, cv::SOLVEPNP_IPPE);
  cv::solvePnPRefineLM(object, pixels, K, D, rvec, tvec);
  std::vector<cv::Point2f> projected;
  cv::projectPoints(object, rvec, tvec, K, D, projected);
  double squared = 0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const cv::Point2f d = projected[i] - pixels[i];
    squared += d.dot(d);
  }

  cv::Mat R;
  cv::Rodrigues(rvec, R);
  // The board's z axis in the camera frame is the plane's normal; the board origin (t) lies on it.
  cv::Vec3d n(R.at<double>(0, 2), R.at<double>(1, 2), R.at<double>(2, 2));
  const cv::Vec3d t(tvec.at<double>(0) / 1000.0, tvec.at<double>(1) / 1000.0,
                    tvec.at<double>(2) / 1000.0);
  double offset = -n.dot(t);  // signed distance of the camera centre from the board plane
  if (std::abs(offset) < 1e-6) throw InputError(image, "the camera lies in the board's plane");
  if (offset < 0) {
    n = -n;
    offset = -offset;
  }
  FloorFromBoard out;
  out.plane.normal = {n[0], n[1], n[2]};
  out.plane.offset = offset + board_thickness_mm / 1000.0;
  out.corners = static_cast<int>(pixels.size());
  out.rms_px = std::sqrt(squared / static_cast<double>(pixels.size()));
  for (int i = 0; i < 3; ++i) {
    out.rotation[i] = rvec.at<double>(i);
    out.translation_m[i] = t[i];
  }
  return out;
}

}  // namespace mocap::camera
