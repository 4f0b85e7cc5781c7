#pragma once
// MoveNet MultiPose on several copies of the detector, each on its own thread (usually one
// single-thread copy per core), working on consecutive frames; detections come back in frame
// order, none lost. When a frame comes in, a free copy starts on it (waiting for one when all are
// busy), and the detections of earlier frames are returned once done. This frame's are waited for
// too when frames come in slowly (live input, idle between frames for more than half a copy's
// time on one): its result then goes out at once instead of with the next frame. Files (frames
// always queued) never wait for the newest frame, so every copy stays busy.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "core/image_buffer.hpp"
#include "detect/movenet_detector.hpp"
#include "detect/ordered_workers.hpp"

namespace mocap::detect {

class MovenetWorkers {
 public:
  // `workers` copies of the detector; options.threads is per copy (0 with several copies: 1, as
  // cv::dnn's default would put one pool per core behind each copy).
  // Throws like MovenetDetector.
  MovenetWorkers(const std::filesystem::path& model_json, MovenetOptions options, int workers);

  // Starts on `image` (its copy shares the pixels, kept alive until done) and returns the people
  // of every frame that is due now, oldest first. Rethrows what a detector threw.
  std::vector<std::vector<MovenetPerson>> push(const ImageBuffer& image);
  // The people of the frames still in work, oldest first.
  std::vector<std::vector<MovenetPerson>> finish();

  // Runs every copy once on a blank image of each size (runtimes built, memory allocated).
  void warm_up(const std::vector<ImageBuffer>& images);

  int workers() const { return pool_.workers(); }
  Backend backend() const { return detectors_.front()->backend(); }

 private:
  using Clock = std::chrono::steady_clock;
  struct Done {
    std::vector<MovenetPerson> people;
    double seconds = 0;  // the copy's time on it
  };
  void take(std::vector<std::vector<MovenetPerson>>& out, bool wait);

  std::vector<std::unique_ptr<MovenetDetector>> detectors_;  // copy i for worker i
  OrderedWorkers<Done> pool_;
  Clock::time_point last_return_{};
  double mean_idle_ = -1, mean_work_ = -1;  // exponential averages, seconds (-1: none yet)
};

}  // namespace mocap::detect
