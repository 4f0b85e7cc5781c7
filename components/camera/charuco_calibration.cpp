#include "camera/charuco_calibration.hpp"

#include <stdexcept>
#include <utility>

#include <opencv2/aruco/charuco.hpp>

#include "camera/board_detection.hpp"
#include "core/input_error.hpp"
#include "core/messages.hpp"

namespace mocap::camera {
namespace {

void check(const CharucoOptions& o) {
  if (o.board.kind != BoardKind::charuco)
    throw std::invalid_argument("ChArUco calibration: the board is not a ChArUco board");
  check_board(o.board);
  if (o.video_step < 1) throw std::invalid_argument("ChArUco: video step must be at least 1");
  if (o.min_corners < 4) throw std::invalid_argument("ChArUco: at least 4 corners per view");
  if (o.min_views < 1) throw std::invalid_argument("ChArUco: at least one view");
}

class Collector {
 public:
  explicit Collector(const CharucoOptions& o) : options_(o) {}

  void add(const std::string& name, const cv::Mat& image) {
    if (image.empty()) {
      result_.skipped.push_back({name, "unreadable image"});
      return;
    }
    if (size_.area() == 0) size_ = image.size();
    if (image.size() != size_) {
      result_.skipped.push_back({name, "size differs from the first image"});
      return;
    }
    detail::BoardDetection found =
        detail::detect_board(detail::to_gray(image), options_.board, options_.min_corners);
    if (!found.found()) {
      result_.skipped.push_back({name, found.reason});
      return;
    }
    corners_.push_back(std::move(found.corners.image));
    ids_.push_back(std::move(found.corners.ids));
    result_.used.push_back(name);
  }

  BoardCalibration finish(const std::string& where) {
    if (static_cast<int>(result_.used.size()) < options_.min_views)
      throw InputError(where, "the board (" + describe(options_.board) + ") was found in " +
                                  std::to_string(result_.used.size()) + " views, at least " +
                                  std::to_string(options_.min_views) + " are needed");
    cv::Mat K, D;
    result_.rms_px = cv::aruco::calibrateCameraCharuco(
        corners_, ids_, detail::charuco_board(options_.board), size_, K, D);
    Camera& c = result_.camera;
    c.name = std::string(kDefaultCamera);
    c.width = size_.width;
    c.height = size_.height;
    c.fx = K.at<double>(0, 0);
    c.fy = K.at<double>(1, 1);
    c.cx = K.at<double>(0, 2);
    c.cy = K.at<double>(1, 2);
    c.distortion.assign(D.begin<double>(), D.end<double>());
    return std::move(result_);
  }

 private:
  CharucoOptions options_;
  std::vector<std::vector<cv::Point2f>> corners_;
  std::vector<std::vector<int>> ids_;
  cv::Size size_;
  BoardCalibration result_;
};

}  // namespace

BoardCalibration calibrate_charuco_images(const std::vector<std::string>& images,
                                          const CharucoOptions& options) {
  check(options);
  Collector collector(options);
  const std::string name = detail::for_each_image(
      images, [&](const std::string& view, const cv::Mat& image) { collector.add(view, image); });
  return collector.finish(name);
}

BoardCalibration calibrate_charuco_video(const std::string& video, const CharucoOptions& options) {
  check(options);
  Collector collector(options);
  detail::for_each_video_frame(
      video, options.video_step,
      [&](const std::string& view, const cv::Mat& frame) { collector.add(view, frame); });
  return collector.finish(video);
}

}  // namespace mocap::camera
