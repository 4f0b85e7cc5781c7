#include "io/trc_writer.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "core/input_error.hpp"

namespace mocap::io {
namespace {

// The counts are rewritten in place: fixed-width fields, digits then spaces (readers trim them).
constexpr int kCountWidth = 10;
constexpr std::int64_t kMaxFrames = 100'000'000;

void append_number(std::string& out, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ec == std::errc() ? end : buf);
}

std::string count_field(std::int64_t count) {
  std::string field = std::to_string(count);
  field.resize(kCountWidth, ' ');
  return field;
}

std::string base_name(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

void check_layout(const TrcLayout& layout, const std::string& path) {
  if (layout.markers.empty()) throw std::invalid_argument("TRC writer: no markers (" + path + ")");
  if (!(layout.rate > 0.0) || !std::isfinite(layout.rate))
    throw std::invalid_argument("TRC writer: the rate must be positive (" + path + ")");
  if (layout.first_frame < 1)
    throw std::invalid_argument("TRC writer: Frame# starts at 1 or later (" + path + ")");
}

// Lines 1-2, then line 3 (the values, counts in fixed-width fields) and lines 4-5.
std::string header_line_1_2(const std::string& file_name) {
  return "PathFileType\t4\t(X/Y/Z)\t" + file_name +
         "\nDataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame"
         "\tOrigNumFrames\n";
}

std::string values_line(const TrcLayout& layout, std::int64_t frames) {
  std::string line;
  append_number(line, layout.rate);
  line += '\t';
  append_number(line, layout.rate);
  line += '\t' + count_field(frames) + '\t' + std::to_string(layout.markers.size()) + "\tm\t";
  append_number(line, layout.rate);
  line += '\t' + std::to_string(layout.first_frame - 1) + '\t' + count_field(frames) + '\n';
  return line;
}

std::string names_lines(const TrcLayout& layout) {
  std::string out = "Frame#\tTime";
  for (const std::string& name : layout.markers) out += '\t' + name + "\t\t";
  out += "\n\t";
  for (std::size_t m = 1; m <= layout.markers.size(); ++m) {
    const std::string n = std::to_string(m);
    out += "\tX" + n + "\tY" + n + "\tZ" + n;
  }
  out += '\n';
  return out;
}

void append_row(std::string& out, std::int64_t frame_number, double rate,
                std::span<const glm::vec3> markers) {
  out += std::to_string(frame_number);
  out += '\t';
  append_number(out, static_cast<double>(frame_number) / rate);
  char buf[48];
  for (const glm::vec3& p : markers) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      out += "\t\t\t";
      continue;
    }
    const int n = std::snprintf(buf, sizeof buf, "\t%.6f\t%.6f\t%.6f", static_cast<double>(p.x),
                                static_cast<double>(p.y), static_cast<double>(p.z));
    out.append(buf, static_cast<std::size_t>(n));
  }
  out += '\n';
}

}  // namespace

std::string format_trc(const std::string& file_name, const TrcLayout& layout,
                       std::span<const std::vector<glm::vec3>> frames) {
  check_layout(layout, file_name);
  std::string out = header_line_1_2(file_name) +
                    values_line(layout, static_cast<std::int64_t>(frames.size())) +
                    names_lines(layout);
  std::int64_t number = layout.first_frame;
  for (const auto& frame : frames) {
    if (frame.size() != layout.markers.size())
      throw std::invalid_argument("TRC writer: " + std::to_string(frame.size()) + " markers for " +
                                  std::to_string(layout.markers.size()) + " (" + file_name + ")");
    append_row(out, number++, layout.rate, frame);
  }
  return out;
}

// The header, with the values line (the counts, rewritten in place) inside one page: a file
// name is at most 255 bytes, so the first three lines always are.
std::string TrcStreamWriter::header(const TrcLayout& layout, const std::string& path,
                                    std::int64_t& values_offset) {
  check_layout(layout, path);
  const std::string lines_1_2 = header_line_1_2(base_name(path));
  values_offset = static_cast<std::int64_t>(lines_1_2.size());
  if (GrowingFile::padding_to_keep_in_one_page(values_offset, values_line(layout, 0).size()) > 0)
    throw std::invalid_argument("TRC writer: file name too long (" + path + ")");
  return lines_1_2 + values_line(layout, 0) + names_lines(layout);
}

TrcStreamWriter::TrcStreamWriter(std::string path, TrcLayout layout)
    : layout_(std::move(layout)),
      file_(path, "TRC file", header(layout_, path, values_offset_),
            /*appear_with_first_line=*/false) {}

void TrcStreamWriter::append(std::span<const glm::vec3> markers) {
  if (markers.size() != layout_.markers.size())
    throw std::invalid_argument("TRC writer: " + std::to_string(markers.size()) + " markers for " +
                                std::to_string(layout_.markers.size()) + " (" + path() + ")");
  if (frames_ >= kMaxFrames)
    throw InputError(path(), "more than " + std::to_string(kMaxFrames) + " frames");
  row_.clear();
  append_row(row_, layout_.first_frame + frames_, layout_.rate, markers);
  file_.append(row_, values_offset_, values_line(layout_, frames_ + 1));
  ++frames_;
}

}  // namespace mocap::io
