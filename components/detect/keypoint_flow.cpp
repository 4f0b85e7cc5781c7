#include "detect/keypoint_flow.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace mocap::detect {

struct KeypointFlow::State {
  cv::Mat gray;
  std::vector<cv::Mat> previous, latest;  // image pyramids (with derivatives)
  std::vector<cv::Point2f> from, forward, backward;
  std::vector<std::uint8_t> forward_ok, backward_ok;
  std::vector<float> error;
  bool have_previous = false, have_latest = false;
};

namespace {

void to_gray(const ImageBuffer& frame, cv::Mat& gray) {
  if (frame.empty() || frame.width() <= 0 || frame.height() <= 0)
    throw std::invalid_argument("optical flow: empty frame");
  const PixelFormat f = frame.format();
  const int channels = bytes_per_pixel(f);
  const cv::Mat view(frame.height(), frame.width(), CV_8UC(channels),
                     const_cast<std::byte*>(frame.data()),
                     static_cast<std::size_t>(frame.stride()));
  switch (f) {
    case PixelFormat::gray8:
      view.copyTo(gray);
      break;
    case PixelFormat::rgb8:
      cv::cvtColor(view, gray, cv::COLOR_RGB2GRAY);
      break;
    case PixelFormat::bgr8:
      cv::cvtColor(view, gray, cv::COLOR_BGR2GRAY);
      break;
    case PixelFormat::rgba8:
      cv::cvtColor(view, gray, cv::COLOR_RGBA2GRAY);
      break;
    case PixelFormat::bgra8:
      cv::cvtColor(view, gray, cv::COLOR_BGRA2GRAY);
      break;
  }
}

}  // namespace

KeypointFlow::KeypointFlow(const KeypointFlowOptions& options)
    : options_(options), state_(std::make_unique<State>()) {
  if (options_.window < 5 || options_.levels < 0)
    throw std::invalid_argument("optical flow: window must be at least 5, levels at least 0");
}

KeypointFlow::~KeypointFlow() = default;

void KeypointFlow::next_frame(const ImageBuffer& frame) {
  State& s = *state_;
  to_gray(frame, s.gray);
  std::swap(s.previous, s.latest);
  s.have_previous = s.have_latest;
  const cv::Size window(options_.window, options_.window);
  cv::buildOpticalFlowPyramid(s.gray, s.latest, window, options_.levels);
  s.have_latest = true;
  // A frame of another size (a new source) has nothing to come from.
  if (s.have_previous && s.previous.front().size() != s.latest.front().size())
    s.have_previous = false;
}

bool KeypointFlow::ready() const { return state_->have_previous && state_->have_latest; }

void KeypointFlow::track(std::span<const FlowPoint> from, std::span<const float> max_error,
                         std::span<FlowPoint> moved, std::span<std::uint8_t> ok) {
  if (max_error.size() != from.size() || moved.size() != from.size() || ok.size() != from.size())
    throw std::invalid_argument("optical flow: spans of different lengths");
  State& s = *state_;
  if (from.empty()) return;
  if (!ready()) {
    std::fill(ok.begin(), ok.end(), std::uint8_t{0});
    return;
  }
  s.from.resize(from.size());
  for (std::size_t i = 0; i < from.size(); ++i) s.from[i] = {from[i].x, from[i].y};
  const cv::Size window(options_.window, options_.window);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  cv::calcOpticalFlowPyrLK(s.previous, s.latest, s.from, s.forward, s.forward_ok, s.error, window,
                           options_.levels, stop);
  s.backward = s.from;  // the starting guess of the way back
  cv::calcOpticalFlowPyrLK(s.latest, s.previous, s.forward, s.backward, s.backward_ok, s.error,
                           window, options_.levels, stop, cv::OPTFLOW_USE_INITIAL_FLOW);
  const cv::Size size = s.latest.front().size();
  for (std::size_t i = 0; i < from.size(); ++i) {
    const cv::Point2f& p = s.forward[i];
    const bool inside = p.x >= 0 && p.y >= 0 && p.x < static_cast<float>(size.width) &&
                        p.y < static_cast<float>(size.height);
    const float back = std::hypot(s.backward[i].x - s.from[i].x, s.backward[i].y - s.from[i].y);
    ok[i] = s.forward_ok[i] && s.backward_ok[i] && inside && back <= max_error[i];
    moved[i] = {p.x, p.y};
  }
}

void KeypointFlow::reset() { state_->have_previous = state_->have_latest = false; }

}  // namespace mocap::detect
