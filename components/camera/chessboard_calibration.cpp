#include "camera/chessboard_calibration.hpp"

#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "camera/board_detection.hpp"
#include "core/input_error.hpp"
#include "core/messages.hpp"

namespace mocap::camera {
namespace {

void check(const ChessboardOptions& o) {
  if (o.inner_columns < 2 || o.inner_rows < 2)
    throw std::invalid_argument("chessboard: at least 2x2 inner corners are needed");
  if (!(o.square_mm > 0)) throw std::invalid_argument("chessboard: square size must be positive");
  if (o.video_step < 1) throw std::invalid_argument("chessboard: video step must be at least 1");
}

// Collects corners of one view after another, then calibrates.
class Collector {
 public:
  explicit Collector(const ChessboardOptions& o) : options_(o) {
    for (int r = 0; r < o.inner_rows; ++r)
      for (int c = 0; c < o.inner_columns; ++c)
        board_.emplace_back(static_cast<float>(c * o.square_mm),
                            static_cast<float>(r * o.square_mm), 0.0f);
  }

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
    cv::Mat gray;
    if (image.channels() == 1)
      gray = image;
    else
      cv::cvtColor(image, gray, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    const cv::Size pattern(options_.inner_columns, options_.inner_rows);
    std::vector<cv::Point2f> corners;
    const bool found = cv::findChessboardCorners(
        gray, pattern, corners,
        cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK);
    if (!found) {
      result_.skipped.push_back({name, "board not found"});
      return;
    }
    cv::cornerSubPix(gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.01));
    image_points_.push_back(std::move(corners));
    result_.used.push_back(name);
  }

  ChessboardCalibration finish(const std::string& where) {
    if (static_cast<int>(result_.used.size()) < options_.min_views)
      throw InputError(where, "the board (" + std::to_string(options_.inner_columns) + "x" +
                                  std::to_string(options_.inner_rows) +
                                  " inner corners) was found in " +
                                  std::to_string(result_.used.size()) + " views, at least " +
                                  std::to_string(options_.min_views) + " are needed");
    const std::vector<std::vector<cv::Point3f>> object_points(image_points_.size(), board_);
    cv::Mat K, D;
    std::vector<cv::Mat> rvecs, tvecs;
    result_.rms_px = cv::calibrateCamera(object_points, image_points_, size_, K, D, rvecs, tvecs);
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
  ChessboardOptions options_;
  std::vector<cv::Point3f> board_;
  std::vector<std::vector<cv::Point2f>> image_points_;
  cv::Size size_;
  ChessboardCalibration result_;
};

}  // namespace

ChessboardCalibration calibrate_chessboard_images(const std::vector<std::string>& images,
                                                  const ChessboardOptions& options) {
  check(options);
  Collector collector(options);
  const std::string name = detail::for_each_image(
      images, [&](const std::string& view, const cv::Mat& image) { collector.add(view, image); });
  return collector.finish(name);
}

ChessboardCalibration calibrate_chessboard_video(const std::string& video,
                                                 const ChessboardOptions& options) {
  check(options);
  Collector collector(options);
  detail::for_each_video_frame(
      video, options.video_step,
      [&](const std::string& view, const cv::Mat& frame) { collector.add(view, frame); });
  return collector.finish(video);
}

}  // namespace mocap::camera
