#pragma once
// Synthetic views of a ChArUco board for tests (there is no real ChArUco photo on the machine):
// the board drawn by cv::aruco::CharucoBoard::draw, warped through a known pinhole camera (no lens
// distortion) at a known pose, then mildly blurred and given Gaussian noise.

#include <cmath>
#include <string>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace mocap::test {

struct CharucoTexture {
  cv::Mat image;           // the board, exactly squares_x x squares_y squares, 8-bit gray
  double mm_per_px = 1.0;  // board millimetres per texture pixel
};

inline CharucoTexture charuco_texture(int squares_x, int squares_y, double square_mm,
                                      double marker_mm, int dictionary, int px_per_square = 60) {
  const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
      squares_x, squares_y, static_cast<float>(square_mm), static_cast<float>(marker_mm),
      cv::aruco::getPredefinedDictionary(dictionary));
  CharucoTexture t;
  board->draw(cv::Size(squares_x * px_per_square, squares_y * px_per_square), t.image, 0, 1);
  t.mm_per_px = square_mm / px_per_square;
  return t;
}

// The board texture seen by camera K (image `size`) with the board frame (texture x right, y down,
// z = 0 on the board; millimetres) at pose (rvec, tvec_mm) board -> camera. Background: gray 110.
inline cv::Mat render_board(const CharucoTexture& texture, const cv::Matx33d& K, cv::Size size,
                            const cv::Vec3d& rvec, const cv::Vec3d& tvec_mm, unsigned seed,
                            double noise_sigma = 2.0) {
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  // Texture pixel centre (u, v) -> board point ((u + 0.5) s, (v + 0.5) s, 0) -> image.
  const double s = texture.mm_per_px;
  const cv::Matx33d to_board(s, 0, 0.5 * s, 0, s, 0.5 * s, 0, 0, 1);
  const cv::Matx33d extrinsic(R(0, 0), R(0, 1), tvec_mm[0], R(1, 0), R(1, 1), tvec_mm[1], R(2, 0),
                              R(2, 1), tvec_mm[2]);
  const cv::Matx33d H = K * extrinsic * to_board;
  cv::Mat out;
  cv::warpPerspective(texture.image, out, cv::Mat(H), size, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                      cv::Scalar(110));
  cv::GaussianBlur(out, out, cv::Size(3, 3), 0.7);
  cv::Mat noise(out.size(), CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
  cv::Mat noisy;
  out.convertTo(noisy, CV_32F);
  noisy += noise;
  noisy.convertTo(out, CV_8U);  // saturates
  return out;
}

// The pose that puts the board's centre (width_mm x height_mm board) at `centre_mm` in the camera
// frame, rotated by `rvec` (board -> camera).
inline cv::Vec3d translation_for_centre(const cv::Vec3d& rvec, double width_mm, double height_mm,
                                        const cv::Vec3d& centre_mm) {
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  return centre_mm - R * cv::Vec3d(0.5 * width_mm, 0.5 * height_mm, 0.0);
}

}  // namespace mocap::test
