#pragma once
// Test pictures as the detectors take them: a cv::Mat wrapped as an ImageBuffer that keeps the
// Mat's pixels alive (no copy), and the reference frame of the detector tests.

#include <filesystem>
#include <memory>

#include <opencv2/core.hpp>

#include "core/image_buffer.hpp"

namespace mocap::test {

// vtest.avi frame 300 (768 x 576, walkers 60-110 px tall), the golden tests' frame.
inline const std::filesystem::path kVtestFrame300 = std::filesystem::path("..") / "shared" /
                                                    "docs" / "models" / "movenet-multipose" /
                                                    "vtest-f300.png";

inline ImageBuffer image_of(const cv::Mat& mat, PixelFormat format = PixelFormat::bgr8) {
  auto owner = std::make_shared<cv::Mat>(mat);  // shares the pixels, counted
  return ImageBuffer(owner->cols, owner->rows, static_cast<int>(owner->step[0]), format, owner,
                     reinterpret_cast<const std::byte*>(owner->data));
}

}  // namespace mocap::test
