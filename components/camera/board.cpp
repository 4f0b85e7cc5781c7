#include "camera/board.hpp"

#include <array>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "camera/board_detection.hpp"
#include "core/input_error.hpp"

namespace mocap::camera {
namespace {

struct Dictionary {
  const char* name;
  cv::aruco::PREDEFINED_DICTIONARY_NAME id;
  int markers;
};

constexpr std::array<Dictionary, 21> kDictionaries{{
    {"DICT_4X4_50", cv::aruco::DICT_4X4_50, 50},
    {"DICT_4X4_100", cv::aruco::DICT_4X4_100, 100},
    {"DICT_4X4_250", cv::aruco::DICT_4X4_250, 250},
    {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000, 1000},
    {"DICT_5X5_50", cv::aruco::DICT_5X5_50, 50},
    {"DICT_5X5_100", cv::aruco::DICT_5X5_100, 100},
    {"DICT_5X5_250", cv::aruco::DICT_5X5_250, 250},
    {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000, 1000},
    {"DICT_6X6_50", cv::aruco::DICT_6X6_50, 50},
    {"DICT_6X6_100", cv::aruco::DICT_6X6_100, 100},
    {"DICT_6X6_250", cv::aruco::DICT_6X6_250, 250},
    {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000, 1000},
    {"DICT_7X7_50", cv::aruco::DICT_7X7_50, 50},
    {"DICT_7X7_100", cv::aruco::DICT_7X7_100, 100},
    {"DICT_7X7_250", cv::aruco::DICT_7X7_250, 250},
    {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000, 1000},
    {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL, 1024},
    {"DICT_APRILTAG_16h5", cv::aruco::DICT_APRILTAG_16h5, 30},
    {"DICT_APRILTAG_25h9", cv::aruco::DICT_APRILTAG_25h9, 35},
    {"DICT_APRILTAG_36h10", cv::aruco::DICT_APRILTAG_36h10, 2320},
    {"DICT_APRILTAG_36h11", cv::aruco::DICT_APRILTAG_36h11, 587},
}};

const Dictionary* find_dictionary(const std::string& name) {
  for (const Dictionary& d : kDictionaries)
    if (name == d.name) return &d;
  return nullptr;
}

std::string format_mm(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

std::vector<std::string> aruco_dictionary_names() {
  std::vector<std::string> names;
  for (const Dictionary& d : kDictionaries) names.emplace_back(d.name);
  return names;
}

void check_board(const BoardSpec& b) {
  const bool charuco = b.kind == BoardKind::charuco;
  if (b.columns < 2 || b.rows < 2 || b.columns > 100 || b.rows > 100)
    throw std::invalid_argument(charuco ? "ChArUco board: 2..100 squares along each side"
                                        : "chessboard: 2..100 inner corners along each side");
  if (!(b.square_mm > 0)) throw std::invalid_argument("board: square size must be positive");
  if (!charuco) return;
  if (!(b.marker_mm > 0 && b.marker_mm < b.square_mm))
    throw std::invalid_argument(
        "ChArUco board: the marker size must be positive and smaller "
        "than the square size");
  const Dictionary* d = find_dictionary(b.dictionary);
  if (!d) {
    std::string names;
    for (const Dictionary& known : kDictionaries) names += std::string(" ") + known.name;
    throw std::invalid_argument("unknown ArUco dictionary '" + b.dictionary + "' (known:" + names +
                                ")");
  }
  const int markers = b.columns * b.rows / 2;
  if (markers > d->markers)
    throw std::invalid_argument("ChArUco board: " + std::to_string(b.columns) + "x" +
                                std::to_string(b.rows) + " squares need " +
                                std::to_string(markers) + " markers, " + b.dictionary + " has " +
                                std::to_string(d->markers));
}

std::string describe(const BoardSpec& b) {
  const std::string size = std::to_string(b.columns) + "x" + std::to_string(b.rows);
  if (b.kind == BoardKind::chessboard)
    return "chessboard " + size + " inner corners, squares " + format_mm(b.square_mm) + " mm";
  return "ChArUco " + size + " squares of " + format_mm(b.square_mm) + " mm, markers " +
         format_mm(b.marker_mm) + " mm, " + b.dictionary;
}

namespace detail {

cv::Mat to_gray(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return gray;
}

cv::Ptr<cv::aruco::CharucoBoard> charuco_board(const BoardSpec& b) {
  check_board(b);
  if (b.kind != BoardKind::charuco) throw std::invalid_argument("not a ChArUco board");
  return cv::aruco::CharucoBoard::create(
      b.columns, b.rows, static_cast<float>(b.square_mm), static_cast<float>(b.marker_mm),
      cv::aruco::getPredefinedDictionary(find_dictionary(b.dictionary)->id));
}

namespace {

BoardDetection detect_chessboard(const cv::Mat& gray, const BoardSpec& b) {
  BoardDetection out;
  const cv::Size pattern(b.columns, b.rows);
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(
          gray, pattern, corners,
          cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK)) {
    out.reason = "board not found";
    return out;
  }
  cv::cornerSubPix(gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.01));
  out.corners.image = std::move(corners);
  for (int r = 0; r < b.rows; ++r)
    for (int c = 0; c < b.columns; ++c)
      out.corners.object.emplace_back(static_cast<float>(c * b.square_mm),
                                      static_cast<float>(r * b.square_mm), 0.0f);
  return out;
}

BoardDetection detect_charuco(const cv::Mat& gray, const BoardSpec& b, int min_corners,
                              const cv::Mat& K, const cv::Mat& D) {
  BoardDetection out;
  const cv::Ptr<cv::aruco::CharucoBoard> board = charuco_board(b);
  std::vector<std::vector<cv::Point2f>> markers, rejected;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(gray, board->dictionary, markers, marker_ids,
                           cv::aruco::DetectorParameters::create(), rejected);
  if (marker_ids.empty()) {
    out.reason = "no ArUco markers of " + b.dictionary + " found";
    return out;
  }
  cv::aruco::refineDetectedMarkers(gray, board, markers, marker_ids, rejected, K, D);
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(markers, marker_ids, gray, board, corners, ids, K, D, 2);
  if (static_cast<int>(ids.size()) < min_corners) {
    out.reason = std::to_string(ids.size()) + " ChArUco corners found, at least " +
                 std::to_string(min_corners) + " are needed";
    return out;
  }
  if (cv::aruco::testCharucoCornersCollinear(board, ids)) {
    out.reason = "the ChArUco corners found lie on one line";
    return out;
  }
  for (int id : ids) out.corners.object.push_back(board->chessboardCorners[id]);
  out.corners.image = std::move(corners);
  out.corners.ids = std::move(ids);
  return out;
}

}  // namespace

BoardDetection detect_board(const cv::Mat& gray, const BoardSpec& board, int min_corners,
                            const cv::Mat& K, const cv::Mat& D) {
  check_board(board);
  if (board.kind == BoardKind::chessboard) return detect_chessboard(gray, board);
  return detect_charuco(gray, board, min_corners, K, D);
}

}  // namespace detail
namespace detail {

std::string for_each_image(const std::vector<std::string>& files, const ViewSink& add) {
  for (const std::string& file : files) {
    cv::Mat image;
    try {
      image = cv::imread(file, cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
      image = cv::Mat();
    }
    add(file, image);
  }
  return files.size() == 1 ? files.front() : std::to_string(files.size()) + " images";
}

void for_each_video_frame(const std::string& video, int step, const ViewSink& add) {
  cv::VideoCapture capture;
  try {
    // A calibration video is a file: FFmpeg reads it (CAP_ANY would go on to GStreamer for a file
    // FFmpeg refuses, which leaks and prints a stack of errors).
    capture.open(video, cv::CAP_FFMPEG);
  } catch (const cv::Exception&) {
  }
  if (!capture.isOpened()) throw InputError(video, "cannot open the video");
  cv::Mat frame;
  for (long index = 0; capture.read(frame); ++index)
    if (index % step == 0) add(video + "#" + std::to_string(index), frame);
}

}  // namespace detail
}  // namespace mocap::camera
