#include "detect/movenet_workers.hpp"

namespace mocap::detect {
namespace {

constexpr double kAverageWeight = 0.2;  // of the newest sample in the running averages

void average(double& mean, double sample) {
  mean = mean < 0 ? sample : (1 - kAverageWeight) * mean + kAverageWeight * sample;
}

}  // namespace

MovenetWorkers::MovenetWorkers(const std::filesystem::path& model_json, MovenetOptions options,
                               int workers)
    : pool_(std::max(workers, 1)) {
  if (pool_.workers() > 1 && options.threads == 0) options.threads = 1;
  for (int i = 0; i < pool_.workers(); ++i)
    detectors_.push_back(std::make_unique<MovenetDetector>(model_json, options));
}

void MovenetWorkers::warm_up(const std::vector<ImageBuffer>& images) {
  for (const ImageBuffer& image : images) {
    for (int i = 0; i < pool_.workers(); ++i)
      pool_.submit([this, &image](int worker) {
        detectors_[static_cast<std::size_t>(worker)]->detect(image);
        return Done{};
      });
    while (pool_.next(true)) {
    }
  }
}

void MovenetWorkers::take(std::vector<std::vector<MovenetPerson>>& out, bool wait) {
  while (auto done = pool_.next(wait)) {
    average(mean_work_, done->seconds);
    out.push_back(std::move(done->people));
  }
}

std::vector<std::vector<MovenetPerson>> MovenetWorkers::push(const ImageBuffer& image) {
  if (last_return_ != Clock::time_point{})
    average(mean_idle_, std::chrono::duration<double>(Clock::now() - last_return_).count());
  pool_.submit([this, image](int worker) {
    const auto start = Clock::now();
    Done done{detectors_[static_cast<std::size_t>(worker)]->detect(image), 0.0};
    done.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return done;
  });
  std::vector<std::vector<MovenetPerson>> out;
  // Older frames are waited for: a copy must be free for the next frame, and their results go out
  // first. This frame too when the input leaves time between frames.
  const bool live = mean_idle_ >= 0 && mean_work_ >= 0 && mean_idle_ > 0.5 * mean_work_;
  while (pool_.pending() >= static_cast<std::size_t>(pool_.workers()) ||
         (live && pool_.pending() > 0)) {
    if (auto done = pool_.next(true)) {
      average(mean_work_, done->seconds);
      out.push_back(std::move(done->people));
    }
  }
  take(out, false);
  last_return_ = Clock::now();
  return out;
}

std::vector<std::vector<MovenetPerson>> MovenetWorkers::finish() {
  std::vector<std::vector<MovenetPerson>> out;
  take(out, true);
  return out;
}

}  // namespace mocap::detect
