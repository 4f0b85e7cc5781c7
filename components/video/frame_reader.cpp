#include "video/frame_reader.hpp"

#include "core/input_error.hpp"

namespace mocap::video {

struct FrameReader::Impl {
  std::string path;
  SourceOptions options;
  std::optional<VideoSource> source;
  std::optional<Frame> last;  // the frame returned last: asked for again, it is not decoded again
  std::int64_t returned = 0, passed_over = 0, reopened = 0;
};

FrameReader::FrameReader(std::string path, SourceOptions options)
    : impl_(std::make_unique<Impl>()) {
  const SourceKind kind = classify(path);
  if (kind == SourceKind::device || kind == SourceKind::network) {
    throw InputError(path, "a " + std::string(name(kind)) +
                               " cannot be read a second time by frame index: connect the "
                               "source's frames instead");
  }
  impl_->path = std::move(path);
  impl_->options = options;
  impl_->source.emplace(impl_->path, options);
}

FrameReader::~FrameReader() = default;
FrameReader::FrameReader(FrameReader&&) noexcept = default;
FrameReader& FrameReader::operator=(FrameReader&&) noexcept = default;

std::optional<Frame> FrameReader::frame(std::int64_t index) {
  Impl& r = *impl_;
  if (index < 0) return std::nullopt;
  if (r.last && r.last->index == index) return r.last;
  if (index < r.source->frames_read()) {
    // Behind the decoder: only a new pass from the start gets there (inter-frame codecs decode
    // from a keyframe, and OpenCV's frame seeking is not exact for every file).
    r.last.reset();
    r.source.emplace(r.path, r.options);
    ++r.reopened;
  }
  while (r.source->frames_read() < index) {
    if (!r.source->skip()) return std::nullopt;
    ++r.passed_over;
  }
  std::optional<Frame> frame = r.source->read();
  if (!frame) return std::nullopt;
  ++r.returned;
  r.last = frame;
  return frame;
}

const std::string& FrameReader::path() const { return impl_->path; }
int FrameReader::width() const { return impl_->source->width(); }
int FrameReader::height() const { return impl_->source->height(); }
std::int64_t FrameReader::returned() const { return impl_->returned; }
std::int64_t FrameReader::passed_over() const { return impl_->passed_over; }
std::int64_t FrameReader::reopened() const { return impl_->reopened; }

}  // namespace mocap::video
