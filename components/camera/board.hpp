#pragma once
// Calibration boards: a chessboard (OpenCV findChessboardCorners) or a ChArUco board (a
// chessboard with ArUco markers in its white squares, cv::aruco), described without OpenCV types.

#include <string>
#include <vector>

namespace mocap::camera {

enum class BoardKind { chessboard, charuco };

struct BoardSpec {
  BoardKind kind = BoardKind::chessboard;
  // Chessboard: inner corners per row (columns) and per column (rows), e.g. 9x6.
  // ChArUco: squares along x and y, e.g. 5x7 (its inner corners are (columns-1)x(rows-1)).
  int columns = 9;
  int rows = 6;
  double square_mm = 25.0;                 // side of one square
  double marker_mm = 0.0;                  // ChArUco: side of one marker (< square_mm)
  std::string dictionary = "DICT_4X4_50";  // ChArUco: a predefined cv::aruco dictionary
};

// Throws std::invalid_argument saying what is wrong: fewer than 2x2 corners (chessboard) or 2x2
// squares (ChArUco), more than 100 along a side, a non-positive size, a marker not smaller than
// its square, an unknown dictionary or one with fewer markers than the board needs.
void check_board(const BoardSpec& board);

// Names of the predefined ArUco dictionaries (DICT_4X4_50 ... DICT_APRILTAG_36h11).
std::vector<std::string> aruco_dictionary_names();

// "chessboard 9x6 inner corners, squares 25 mm" / "ChArUco 5x7 squares of 40 mm, markers 30 mm,
// DICT_4X4_50".
std::string describe(const BoardSpec& board);

}  // namespace mocap::camera
