#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/input_error.hpp"
#include "motion/bvh.hpp"

namespace mocap::motion {
namespace {

// Splits BVH text into whitespace-separated tokens, keeping the line of each for messages.
class Tokenizer {
 public:
  Tokenizer(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  bool at_end() {
    skip_space();
    return pos_ >= text_.size();
  }

  std::string_view next(const char* what) {
    skip_space();
    if (pos_ >= text_.size()) fail(std::string("unexpected end of file, expected ") + what);
    const size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    return text_.substr(start, pos_ - start);
  }

  void expect(std::string_view word) {
    const std::string_view got = next(std::string(word).c_str());
    if (got != word) fail("expected '" + std::string(word) + "', found '" + std::string(got) + "'");
  }

  float number(const char* what) {
    std::string_view tok = next(what);
    const std::string_view original = tok;
    if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
    float value = 0.0f;
    const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), value);
    if (ec == std::errc::result_out_of_range) {
      fail(std::string("number out of range for ") + what + ": '" + std::string(original) + "'");
    }
    if (ec != std::errc() || end != tok.data() + tok.size() || !std::isfinite(value)) {
      fail(std::string("expected a number for ") + what + ", found '" + std::string(original) +
           "'");
    }
    return value;
  }

  long integer(const char* what) {
    const std::string_view tok = next(what);
    long value = 0;
    const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), value);
    if (ec != std::errc() || end != tok.data() + tok.size()) {
      fail(std::string("expected a whole number for ") + what + ", found '" + std::string(tok) +
           "'");
    }
    return value;
  }

  // The text after the last token read, from its first non-space character.
  std::string_view rest() {
    skip_space();
    return text_.substr(pos_);
  }

  [[noreturn]] void fail(const std::string& what) const { throw InputError(source_, line_, what); }
  long line() const { return line_; }

 private:
  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }

  std::string_view text_;
  const std::string& source_;
  size_t pos_ = 0;
  long line_ = 1;
};

Channel parse_channel(Tokenizer& tok) {
  const std::string_view name = tok.next("a channel name");
  static constexpr std::pair<std::string_view, Channel> kNames[] = {
      {"Xposition", Channel::Xposition}, {"Yposition", Channel::Yposition},
      {"Zposition", Channel::Zposition}, {"Xrotation", Channel::Xrotation},
      {"Yrotation", Channel::Yrotation}, {"Zrotation", Channel::Zrotation}};
  for (const auto& [text, channel] : kNames) {
    // Some exporters write lower-case channel names; accept them.
    if (text.size() == name.size() &&
        std::equal(text.begin(), text.end(), name.begin(), [](char a, char b) {
          return std::tolower(static_cast<unsigned char>(a)) ==
                 std::tolower(static_cast<unsigned char>(b));
        })) {
      return channel;
    }
  }
  tok.fail("unknown channel '" + std::string(name) + "'");
}

constexpr int kMaxJoints = 10000;
constexpr int kMaxDepth = 1000;

void parse_joint(Tokenizer& tok, Skeleton& skel, int parent, bool end_site, int depth) {
  if (depth > kMaxDepth) tok.fail("hierarchy nested deeper than " + std::to_string(kMaxDepth));
  if (skel.joint_count() >= kMaxJoints)
    tok.fail("more than " + std::to_string(kMaxJoints) + " joints");
  SkeletonJoint joint;
  joint.parent = parent;
  joint.end_site = end_site;
  if (end_site) {
    tok.expect("Site");
    joint.name = (parent >= 0 ? skel.joints[parent].name : std::string()) + "_End";
  } else {
    joint.name = std::string(tok.next("a joint name"));
    if (joint.name == "{") tok.fail("joint has no name");
  }
  tok.expect("{");
  tok.expect("OFFSET");
  joint.offset.x = tok.number("OFFSET x");
  joint.offset.y = tok.number("OFFSET y");
  joint.offset.z = tok.number("OFFSET z");
  const int index = skel.joint_count();
  if (!end_site) {
    tok.expect("CHANNELS");
    const long n = tok.integer("the channel count");
    if (n < 0 || n > 6) tok.fail("channel count must be 0 to 6, found " + std::to_string(n));
    for (long c = 0; c < n; ++c) {
      const Channel channel = parse_channel(tok);
      // A channel named twice leaves its meaning (and the rotation order) undefined.
      if (std::find(joint.channels.begin(), joint.channels.end(), channel) != joint.channels.end())
        tok.fail(std::string("channel ") + channel_name(channel) + " listed twice for joint '" +
                 joint.name + "'");
      joint.channels.push_back(channel);
    }
  }
  skel.joints.push_back(std::move(joint));
  for (;;) {
    const std::string_view word = tok.next("'JOINT', 'End Site' or '}'");
    if (word == "}") return;
    if (word == "JOINT" && !end_site) {
      parse_joint(tok, skel, index, false, depth + 1);
    } else if (word == "End" && !end_site) {
      parse_joint(tok, skel, index, true, depth + 1);
    } else {
      tok.fail("expected 'JOINT', 'End Site' or '}', found '" + std::string(word) + "'");
    }
  }
}

void parse_frame_header(Tokenizer& tok, Clip& clip) {
  // "Frames: N" and "Frame Time: T"; the colon may stand apart, tabs or spaces around it.
  std::string_view word = tok.next("'Frames:'");
  if (word == "Frames") {
    tok.expect(":");
  } else if (word != "Frames:") {
    tok.fail("expected 'Frames:', found '" + std::string(word) + "'");
  }
  const long frames = tok.integer("the frame count");
  if (frames < 0 || frames > 100'000'000)
    tok.fail("implausible frame count " + std::to_string(frames));
  clip.frame_count = static_cast<int>(frames);
  tok.expect("Frame");
  word = tok.next("'Time:'");
  if (word == "Time") {
    tok.expect(":");
  } else if (word != "Time:") {
    tok.fail("expected 'Time:', found '" + std::string(word) + "'");
  }
  const float frame_time = tok.number("the frame time");
  if (!(frame_time > 0.0f)) tok.fail("frame time must be positive");
  clip.frame_time = frame_time;
}

// A writer that streams frames (BvhStreamWriter) appends a frame's line before it raises the
// frame count; a process killed between the two leaves one frame line, possibly cut short, after
// the declared frames. That one line is ignored; anything longer is still an error.
bool is_one_unfinished_frame(std::string_view rest, int channels) {
  const size_t newline = rest.find('\n');
  const std::string_view after = newline == std::string_view::npos ? "" : rest.substr(newline);
  if (!std::all_of(after.begin(), after.end(),
                   [](char c) { return std::isspace(static_cast<unsigned char>(c)); })) {
    return false;
  }
  const std::string_view line = rest.substr(0, newline);
  int values = 0;
  for (size_t i = 0; i < line.size(); ++i) {
    const bool starts_token = !std::isspace(static_cast<unsigned char>(line[i])) &&
                              (i == 0 || std::isspace(static_cast<unsigned char>(line[i - 1])));
    values += starts_token ? 1 : 0;
  }
  return values <= channels;
}

}  // namespace

Clip parse_bvh(std::string_view text, const std::string& source) {
  Tokenizer tok(text, source);
  Clip clip;
  clip.source = source;
  tok.expect("HIERARCHY");
  std::string_view word = tok.next("'ROOT'");
  if (word != "ROOT") tok.fail("expected 'ROOT', found '" + std::string(word) + "'");
  for (;;) {
    parse_joint(tok, clip.skeleton, -1, false, 0);
    word = tok.next("'ROOT' or 'MOTION'");
    if (word == "MOTION") break;
    if (word != "ROOT") tok.fail("expected 'ROOT' or 'MOTION', found '" + std::string(word) + "'");
  }
  clip.skeleton.assign_channel_slots();
  parse_frame_header(tok, clip);
  const int channels = clip.skeleton.channel_count;
  if (channels == 0 && clip.frame_count > 0)
    tok.fail("frames given but the hierarchy has no channels");
  // Each value takes at least two bytes of text: refuse counts the file cannot hold before
  // allocating for them.
  const size_t total = static_cast<size_t>(clip.frame_count) * static_cast<size_t>(channels);
  if (total > text.size() / 2 + 1) {
    tok.fail("file is truncated: " + std::to_string(clip.frame_count) + " frames of " +
             std::to_string(channels) + " channels declared, far more than the file holds");
  }
  clip.values.resize(total);
  for (int f = 0; f < clip.frame_count; ++f) {
    float* row = clip.frame(f);
    for (int c = 0; c < channels; ++c) {
      if (tok.at_end()) {
        tok.fail("file is truncated: frame " + std::to_string(f) + " has " + std::to_string(c) +
                 " of " + std::to_string(channels) + " values (" +
                 std::to_string(clip.frame_count) + " frames declared)");
      }
      row[c] = tok.number("a channel value");
    }
  }
  if (!tok.at_end() && !is_one_unfinished_frame(tok.rest(), channels)) {
    tok.fail("more values than the " + std::to_string(clip.frame_count) +
             " frames the header declares");
  }
  return clip;
}

Clip read_bvh(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw InputError(path, "read error");
  return parse_bvh(buffer.str(), path);
}

}  // namespace mocap::motion
