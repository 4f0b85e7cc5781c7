#include "io/trc.hpp"

#include <charconv>
#include <cmath>
#include <limits>

#include "core/input_error.hpp"
#include "io/read_file.hpp"

namespace mocap::io {

namespace {

std::vector<std::string_view> split_tabs(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const auto tab = line.find('\t', start);
    out.push_back(line.substr(start, tab == std::string_view::npos ? tab : tab - start));
    if (tab == std::string_view::npos) break;
    start = tab + 1;
  }
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

bool to_double(std::string_view s, double& v) {
  s = trim(s);
  if (s.empty()) return false;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && ptr == s.data() + s.size();
}

bool only_blank_after(const std::vector<std::string_view>& lines, std::size_t from) {
  for (std::size_t l = from; l < lines.size(); ++l)
    if (!trim(lines[l]).empty()) return false;
  return true;
}

}  // namespace

std::optional<std::size_t> TrcFile::marker(std::string_view name) const {
  for (std::size_t i = 0; i < markers.size(); ++i)
    if (markers[i] == name) return i;
  return std::nullopt;
}

TrcFile parse_trc(std::string_view text, const std::string& file) {
  std::vector<std::string_view> lines;
  std::size_t pos = 0;
  while (pos < text.size()) {
    auto end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    lines.push_back(text.substr(pos, end - pos));
    pos = end + 1;
  }
  const auto fail = [&](long line, const std::string& what) -> InputError {
    return InputError(file, line, what);
  };
  if (lines.empty() || !lines[0].starts_with("PathFileType"))
    throw fail(1, "not a TRC file (expected 'PathFileType' on line 1)");
  if (lines.size() < 5) throw fail(static_cast<long>(lines.size()), "TRC header truncated");
  const auto keys = split_tabs(lines[1]);
  const auto values = split_tabs(lines[2]);
  TrcFile out;
  out.path = file;
  long num_markers = -1, num_frames = -1;
  double scale = 0.0;
  for (std::size_t i = 0; i < keys.size() && i < values.size(); ++i) {
    const std::string_view key = trim(keys[i]), value = trim(values[i]);
    double v = 0.0;
    if (key == "DataRate" && to_double(value, v) && v > 0 && v < 1e6) out.rate = v;
    if (key == "NumMarkers" && to_double(value, v) && v >= 1 && v <= 10000)
      num_markers = static_cast<long>(v);
    if (key == "NumFrames" && to_double(value, v) && v >= 0 && v <= 1e7)
      num_frames = static_cast<long>(v);
    if (key == "Units") {
      if (value == "m")
        scale = 1.0;
      else if (value == "mm")
        scale = 0.001;
      else if (value == "cm")
        scale = 0.01;
      else
        throw fail(3, "unknown Units '" + std::string(value) + "' (m, cm, mm)");
    }
  }
  if (num_markers < 0) throw fail(3, "no valid NumMarkers in the header");
  if (scale == 0.0) throw fail(3, "no Units in the header");
  const auto names = split_tabs(lines[3]);
  if (names.size() < 2 || trim(names[0]) != "Frame#")
    throw fail(4, "expected 'Frame#', 'Time' and the marker names");
  for (std::size_t i = 2; i < names.size(); ++i)
    if (!trim(names[i]).empty()) out.markers.emplace_back(trim(names[i]));
  if (static_cast<long>(out.markers.size()) != num_markers)
    throw fail(4, std::to_string(out.markers.size()) + " marker names, NumMarkers says " +
                      std::to_string(num_markers));
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t l = 5; l < lines.size(); ++l) {
    if (trim(lines[l]).empty()) continue;
    if (num_frames >= 0 && static_cast<long>(out.frames.size()) == num_frames &&
        only_blank_after(lines, l + 1))
      break;  // one row beyond the count, last: a streaming writer killed before counting it
    const auto cells = split_tabs(lines[l]);
    const std::size_t wanted = 2 + 3 * out.markers.size();
    if (cells.size() < wanted)
      throw fail(static_cast<long>(l + 1), "row has " + std::to_string(cells.size()) +
                                               " cells, expected " + std::to_string(wanted) +
                                               " (file truncated?)");
    double frame = 0.0;
    if (!to_double(cells[0], frame)) throw fail(static_cast<long>(l + 1), "Frame# is not a number");
    std::vector<glm::vec3> row(out.markers.size(), glm::vec3(nan));
    for (std::size_t m = 0; m < out.markers.size(); ++m) {
      double xyz[3];
      bool empty = true, ok = true;
      for (int c = 0; c < 3; ++c) {
        const std::string_view cell = trim(cells[2 + 3 * m + c]);
        if (!cell.empty()) empty = false;
        ok = ok && to_double(cell, xyz[c]) && std::isfinite(xyz[c]);
      }
      if (empty) continue;  // an empty cell: the marker is missing in this frame
      if (!ok)
        throw fail(static_cast<long>(l + 1),
                   "marker '" + out.markers[m] + "' has a cell that is not a number");
      row[m] = glm::vec3(static_cast<float>(xyz[0] * scale), static_cast<float>(xyz[1] * scale),
                         static_cast<float>(xyz[2] * scale));
    }
    out.frames.push_back(std::move(row));
  }
  if (num_frames >= 0 && static_cast<long>(out.frames.size()) != num_frames)
    throw fail(static_cast<long>(lines.size()),
               std::to_string(out.frames.size()) + " data rows, NumFrames says " +
                   std::to_string(num_frames) + " (file truncated?)");
  return out;
}

TrcFile read_trc(const std::filesystem::path& file) {
  return parse_trc(read_whole_file(file, 512u << 20), file.string());
}

}  // namespace mocap::io
