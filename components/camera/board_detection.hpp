#pragma once
// Internal to mocap_camera (OpenCV types; included only by its .cpp files): finding a chessboard
// or ChArUco board in one image.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "camera/board.hpp"

namespace cv::aruco {
class CharucoBoard;
}

namespace mocap::camera::detail {

struct BoardCorners {
  std::vector<cv::Point3f> object;  // board frame, millimetres, z = 0
  std::vector<cv::Point2f> image;   // pixels, sub-pixel refined
  std::vector<int> ids;             // ChArUco corner ids (empty for a chessboard)
};

struct BoardDetection {
  BoardCorners corners;
  std::string reason;  // why the board was not found; empty when it was
  bool found() const { return reason.empty(); }
};

// `image` in any of 1, 3 (BGR) or 4 (BGRA) channels -> 8-bit grayscale.
cv::Mat to_gray(const cv::Mat& image);

// Finds the board (check_board(board) first). A ChArUco board needs at least `min_corners`
// corners that are not collinear; K and D (optional) help its corner interpolation.
BoardDetection detect_board(const cv::Mat& gray, const BoardSpec& board, int min_corners,
                            const cv::Mat& K = {}, const cv::Mat& D = {});

// What a calibration does with each view: its name (file, or video#frame) and its pixels (empty
// when the file could not be decoded: the calibration says so).
using ViewSink = std::function<void(const std::string& name, const cv::Mat& image)>;

// Every image file, decoded in colour. Returns what the calibration calls them: the file for one
// image, "N images" for several.
std::string for_each_image(const std::vector<std::string>& files, const ViewSink& add);

// Every `step`-th frame of a video file, named video#index. Throws InputError naming the video
// when it cannot be opened.
void for_each_video_frame(const std::string& video, int step, const ViewSink& add);

// The cv::aruco board of a ChArUco spec (millimetres).
cv::Ptr<cv::aruco::CharucoBoard> charuco_board(const BoardSpec& board);

}  // namespace mocap::camera::detail
