#pragma once
// Camera intrinsics from ChArUco board images or a video (cv::aruco detectMarkers,
// interpolateCornersCharuco, calibrateCameraCharuco). A ChArUco board may be partly hidden or
// outside the image: every view with enough corners counts.

#include <string>
#include <vector>

#include "camera/board.hpp"
#include "camera/chessboard_calibration.hpp"

namespace mocap::camera {

struct CharucoOptions {
  BoardSpec board{BoardKind::charuco, 5, 7, 40.0, 30.0, "DICT_4X4_50"};
  int video_step = 15;  // every Nth frame of a video is tried
  int min_views = 3;    // fewer views with the board -> InputError
  int min_corners = 6;  // a view with fewer ChArUco corners is skipped
};

// Calibrates from image files in the given order. Views are skipped with a reason ("unreadable
// image", "size differs from the first image", "no ArUco markers of DICT_... found", "N ChArUco
// corners found, at least M are needed", "the ChArUco corners found lie on one line"). Throws
// InputError naming the inputs when fewer than options.min_views views remain;
// std::invalid_argument for a bad board (check_board) or options.
BoardCalibration calibrate_charuco_images(const std::vector<std::string>& images,
                                          const CharucoOptions& options);

// Calibrates from every options.video_step-th frame of a video file. Throws InputError naming the
// file when it cannot be opened or too few views have the board.
BoardCalibration calibrate_charuco_video(const std::string& video, const CharucoOptions& options);

}  // namespace mocap::camera
