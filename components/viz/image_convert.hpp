#pragma once
// ImageBuffer <-> cv::Mat without copies where possible. Internal to the viz library: it includes
// OpenCV, which no widely included header of the project does.

#include <opencv2/core.hpp>

#include "core/image_buffer.hpp"

namespace mocap::viz {

// A writable view of a buffer this code has just made (before it is shared).
cv::Mat as_mat(ImageBuffer& image);
// A read-only view of any buffer (its pixel format decides the channels).
cv::Mat view_of(const ImageBuffer& image);
// The image as 8-bit BGR: the view itself when it already is, a converted copy otherwise.
cv::Mat to_bgr(const ImageBuffer& image);

}  // namespace mocap::viz
