#pragma once
// Camera intrinsics from chessboard images or a video (OpenCV findChessboardCorners, cornerSubPix,
// calibrateCamera).

#include <string>
#include <vector>

#include "camera/camera.hpp"

namespace mocap::camera {

struct ChessboardOptions {
  int inner_columns = 9;  // inner corners per row
  int inner_rows = 6;     // inner corners per column
  double square_mm = 1.0;
  int video_step = 15;  // every Nth frame of a video is tried
  int min_views = 3;    // fewer boards found -> InputError
};

struct SkippedView {
  std::string name;    // file, or "<video>#<frame>"
  std::string reason;  // "unreadable image", "board not found", "size differs ..."
};

// What a calibration from board views found (chessboard here, ChArUco in charuco_calibration.hpp).
struct BoardCalibration {
  Camera camera;                  // intrinsics, named cam_01, at the world origin
  double rms_px = 0.0;            // RMS reprojection error over all corners
  std::vector<std::string> used;  // views whose board was found
  std::vector<SkippedView> skipped;
};
using ChessboardCalibration = BoardCalibration;

// Calibrates from image files (any format OpenCV reads) in the given order. Throws InputError when
// fewer than options.min_views boards are found, naming the inputs; std::invalid_argument for a
// board smaller than 2x2 or a non-positive square size.
ChessboardCalibration calibrate_chessboard_images(const std::vector<std::string>& images,
                                                  const ChessboardOptions& options);

// Calibrates from every options.video_step-th frame of a video file. Throws InputError naming the
// file when it cannot be opened or too few boards are found.
ChessboardCalibration calibrate_chessboard_video(const std::string& video,
                                                 const ChessboardOptions& options);

}  // namespace mocap::camera
