#include "motion/bvh_stream_writer.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "core/input_error.hpp"
#include "motion/bvh.hpp"

namespace mocap::motion {
namespace {

constexpr int kCountDigits = 10;

Skeleton with_channel_slots(Skeleton skeleton) {
  skeleton.assign_channel_slots();
  return skeleton;
}

}  // namespace

BvhStreamWriter::BvhStreamWriter(std::string path, Skeleton skeleton, double frame_time)
    : skeleton_(with_channel_slots(std::move(skeleton))),
      header_(header(skeleton_, frame_time, path)),
      file_(std::move(path), "BVH file", header_.text, /*appear_with_first_line=*/true) {
  header_.text = {};  // written
}

BvhStreamWriter::Header BvhStreamWriter::header(const Skeleton& skeleton, double frame_time,
                                                const std::string& path) {
  if (skeleton.channel_count == 0)
    throw std::invalid_argument("BvhStreamWriter: the skeleton has no channels (" + path + ")");
  if (!(frame_time > 0.0) || !std::isfinite(frame_time))
    throw std::invalid_argument("BvhStreamWriter: frame time must be positive (" + path + ")");
  std::ostringstream text;
  write_bvh_hierarchy(skeleton, text);
  Header h{std::move(text).str() + "MOTION"};
  const std::string count_label = "\nFrames: ";
  const auto digits_at = static_cast<std::int64_t>(h.text.size() + count_label.size());
  // The count is rewritten after every frame: keep its digits inside one page.
  h.text.append(GrowingFile::padding_to_keep_in_one_page(digits_at, kCountDigits), ' ');
  h.text += count_label;
  h.count_offset = static_cast<std::int64_t>(h.text.size());
  h.text.append(kCountDigits, '0');
  h.text += "\nFrame Time: ";
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, frame_time);
  h.text.append(buf, end);
  h.text += '\n';
  return h;
}

void BvhStreamWriter::append(std::span<const float> values) {
  if (values.size() != static_cast<std::size_t>(skeleton_.channel_count)) {
    throw std::invalid_argument("BvhStreamWriter: " + std::to_string(values.size()) +
                                " values for " + std::to_string(skeleton_.channel_count) +
                                " channels (" + path() + ")");
  }
  for (float v : values) {
    if (!std::isfinite(v))
      throw std::invalid_argument("BvhStreamWriter: non-finite channel value (" + path() + ")");
  }
  if (frames_ >= kMaxFrames)
    throw InputError(path(), "more than " + std::to_string(kMaxFrames) + " frames");
  line_.clear();
  append_bvh_frame_line(values, line_);
  char digits[24];  // frames <= kMaxFrames: always kCountDigits digits
  std::snprintf(digits, sizeof digits, "%0*lld", kCountDigits, static_cast<long long>(frames_ + 1));
  file_.append(line_, header_.count_offset, std::string_view(digits, kCountDigits));
  ++frames_;
}

}  // namespace mocap::motion
