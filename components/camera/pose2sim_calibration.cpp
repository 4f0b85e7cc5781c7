#include "camera/pose2sim_calibration.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <sstream>

#include <glm/geometric.hpp>

#include "core/input_error.hpp"

namespace mocap::camera {
namespace {

constexpr std::uintmax_t kMaxFileBytes = 1u << 20;  // a calibration of many cameras is ~1 KB each
constexpr int kMaxDepth = 8;                        // array nesting

struct Value {
  enum class Kind { number, string, boolean, array } kind = Kind::number;
  double number = 0.0;
  std::string text;
  bool boolean = false;
  std::vector<Value> items;
  long line = 0;
};

struct Table {
  std::string name;
  long line = 0;
  std::map<std::string, Value, std::less<>> keys;
};

// The TOML subset of Pose2Sim's calibration files, parsed in one pass.
class Parser {
 public:
  Parser(std::string_view text, const std::string& file) : text_(text), file_(file) {}

  std::vector<Table> parse() {
    std::vector<Table> tables;
    while (true) {
      skip_blank_lines();
      if (at_end()) break;
      const char c = text_[pos_];
      if (c == '[') {
        tables.push_back(parse_header());
        for (std::size_t i = 0; i + 1 < tables.size(); ++i)
          if (tables[i].name == tables.back().name)
            fail("table [" + tables.back().name + "] appears twice");
        continue;
      }
      if (tables.empty()) fail("a key before any [table]");
      Table& table = tables.back();
      const long line = line_;
      const std::string key = parse_key();
      skip_spaces();
      expect('=', "'=' after key '" + key + "'");
      skip_spaces();
      Value value = parse_value(0, table.name, key);
      value.line = line;
      end_of_statement();
      if (!table.keys.emplace(key, std::move(value)).second)
        fail("[" + table.name + "] key '" + key + "' appears twice");
    }
    return tables;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw InputError(file_, line_, what); }

  bool at_end() const { return pos_ >= text_.size(); }

  void skip_spaces() {
    while (!at_end() && (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\r')) ++pos_;
  }
  void skip_comment() {
    if (!at_end() && text_[pos_] == '#')
      while (!at_end() && text_[pos_] != '\n') ++pos_;
  }
  void skip_blank_lines() {
    while (true) {
      skip_spaces();
      skip_comment();
      if (at_end() || text_[pos_] != '\n') return;
      ++pos_;
      ++line_;
    }
  }
  // Spaces, comments and line breaks (inside arrays).
  void skip_space_and_newlines() { skip_blank_lines(); }

  void expect(char c, const std::string& what) {
    if (at_end()) fail("file ends where " + what + " was expected (truncated?)");
    if (text_[pos_] != c) fail("expected " + what + ", found " + describe(text_[pos_]));
    ++pos_;
  }

  static std::string describe(char c) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) return std::string("'") + c + "'";
    std::ostringstream s;
    s << "byte 0x" << std::hex << static_cast<int>(u);
    return s.str();
  }

  void end_of_statement() {
    skip_spaces();
    skip_comment();
    if (at_end()) return;
    if (text_[pos_] != '\n') fail("unexpected " + describe(text_[pos_]) + " after a value");
  }

  static bool bare_key_char(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  }

  std::string parse_key() {
    const std::size_t start = pos_;
    while (!at_end() && bare_key_char(text_[pos_])) ++pos_;
    if (pos_ == start)
      fail("expected a key or a [table], found " +
           (at_end() ? std::string("the end") : describe(text_[pos_])));
    return std::string(text_.substr(start, pos_ - start));
  }

  Table parse_header() {
    Table table;
    table.line = line_;
    ++pos_;  // '['
    if (!at_end() && text_[pos_] == '[') fail("arrays of tables ([[...]]) are not supported");
    skip_spaces();
    const std::size_t start = pos_;
    while (!at_end() && (bare_key_char(text_[pos_]) || text_[pos_] == '.')) ++pos_;
    if (pos_ == start) fail("empty or invalid table name");
    table.name = std::string(text_.substr(start, pos_ - start));
    skip_spaces();
    expect(']', "']' closing table [" + table.name);
    end_of_statement();
    return table;
  }

  Value parse_value(int depth, const std::string& table, const std::string& key) {
    const std::string where = "[" + table + "] " + key + ": ";
    if (at_end()) fail(where + "value missing (truncated?)");
    Value v;
    v.line = line_;
    const char c = text_[pos_];
    if (c == '"') {
      v.kind = Value::Kind::string;
      ++pos_;
      while (true) {
        if (at_end() || text_[pos_] == '\n') fail(where + "unterminated string");
        const char d = text_[pos_++];
        if (d == '"') break;
        if (d == '\\') {
          if (at_end()) fail(where + "unterminated string");
          const char e = text_[pos_++];
          if (e != '"' && e != '\\') fail(where + "unsupported escape \\" + std::string(1, e));
          v.text += e;
        } else {
          v.text += d;
        }
      }
      return v;
    }
    if (c == '[') {
      if (depth >= kMaxDepth) fail(where + "arrays nested too deeply");
      v.kind = Value::Kind::array;
      ++pos_;
      while (true) {
        skip_space_and_newlines();
        if (at_end()) fail(where + "file ends inside an array (truncated?)");
        if (text_[pos_] == ']') {
          ++pos_;
          return v;
        }
        v.items.push_back(parse_value(depth + 1, table, key));
        skip_space_and_newlines();
        if (at_end()) fail(where + "file ends inside an array (truncated?)");
        if (text_[pos_] == ',') {
          ++pos_;
        } else if (text_[pos_] != ']') {
          fail(where + "expected ',' or ']' in an array, found " + describe(text_[pos_]));
        }
      }
    }
    if (text_.substr(pos_).starts_with("true") || text_.substr(pos_).starts_with("false")) {
      v.kind = Value::Kind::boolean;
      v.boolean = c == 't';
      pos_ += v.boolean ? 4 : 5;
      return v;
    }
    std::size_t start = pos_;
    if (c == '+') start = ++pos_;
    const char* first = text_.data() + start;
    const char* last = text_.data() + text_.size();
    const auto [end, ec] = std::from_chars(first, last, v.number);
    if (ec != std::errc() || end == first)
      fail(where + "expected a number, string, boolean or array, found " + describe(c));
    if (!std::isfinite(v.number)) fail(where + "non-finite number");
    pos_ = static_cast<std::size_t>(end - text_.data());
    return v;
  }

  std::string_view text_;
  const std::string& file_;
  std::size_t pos_ = 0;
  long line_ = 1;
};

// Typed access to one table's keys; errors name the file, the line, the table and the key.
class Keys {
 public:
  Keys(const Table& table, const std::string& file) : table_(table), file_(file) {}

  const Value& get(const std::string& key) const {
    const auto found = table_.keys.find(key);
    if (found == table_.keys.end())
      throw InputError(file_, table_.line,
                       "[" + table_.name + "]: missing key '" + key + "' (file truncated?)");
    return found->second;
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(file_, get(key).line, "[" + table_.name + "] " + key + ": " + what);
  }
  bool has(const std::string& key) const { return table_.keys.contains(key); }

  std::string string(const std::string& key) const {
    const Value& v = get(key);
    if (v.kind != Value::Kind::string) fail(key, "expected a string");
    return v.text;
  }
  bool boolean(const std::string& key) const {
    const Value& v = get(key);
    if (v.kind != Value::Kind::boolean) fail(key, "expected true or false");
    return v.boolean;
  }
  // A flat array of numbers; `count` < 0: any length.
  std::vector<double> numbers(const std::string& key, int count) const {
    return numbers_of(get(key), key, count);
  }
  std::vector<double> numbers_of(const Value& v, const std::string& key, int count) const {
    if (v.kind != Value::Kind::array) fail(key, "expected an array of numbers");
    std::vector<double> out;
    for (const Value& item : v.items) {
      if (item.kind != Value::Kind::number) fail(key, "expected an array of numbers");
      out.push_back(item.number);
    }
    if (count >= 0 && out.size() != static_cast<std::size_t>(count))
      fail(key,
           "expected " + std::to_string(count) + " numbers, found " + std::to_string(out.size()));
    return out;
  }
  std::array<double, 9> matrix3(const std::string& key) const {
    const Value& v = get(key);
    if (v.kind != Value::Kind::array || v.items.size() != 3) fail(key, "expected a 3x3 matrix");
    std::array<double, 9> m{};
    for (int r = 0; r < 3; ++r) {
      const auto row = numbers_of(v.items[r], key, 3);
      for (int c = 0; c < 3; ++c) m[3 * r + c] = row[c];
    }
    return m;
  }

 private:
  const Table& table_;
  const std::string& file_;
};

Pose2SimCamera camera_of(const Table& table, const std::string& file) {
  const Keys keys(table, file);
  Pose2SimCamera cam;
  cam.section = table.name;
  cam.name = keys.string("name");
  const auto size = keys.numbers("size", 2);
  if (!(size[0] >= 1 && size[1] >= 1 && size[0] <= 1e5 && size[1] <= 1e5) ||
      size[0] != std::floor(size[0]) || size[1] != std::floor(size[1]))
    keys.fail("size", "expected two positive whole numbers of pixels");
  cam.intrinsics.width = static_cast<int>(size[0]);
  cam.intrinsics.height = static_cast<int>(size[1]);
  cam.intrinsics.K = keys.matrix3("matrix");
  const auto& K = cam.intrinsics.K;
  if (!(K[0] > 0 && K[4] > 0) || K[3] != 0 || K[6] != 0 || K[7] != 0 || K[8] != 1)
    keys.fail("matrix", "expected [[fx, s, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0");
  cam.intrinsics.distortion = keys.numbers("distortions", -1);
  if (cam.intrinsics.distortion.size() > 14) keys.fail("distortions", "more than 14 coefficients");
  const auto r = keys.numbers("rotation", 3);
  cam.rotation = {r[0], r[1], r[2]};
  const auto t = keys.numbers("translation", 3);
  cam.translation = {t[0], t[1], t[2]};
  if (keys.has("fisheye")) cam.fisheye = keys.boolean("fisheye");
  return cam;
}

}  // namespace

glm::dmat3 rodrigues(const glm::dvec3& r) {
  const double theta = glm::length(r);
  if (theta < 1e-12) return glm::dmat3(1.0);
  const glm::dvec3 k = r / theta;
  const double c = std::cos(theta), s = std::sin(theta), C = 1.0 - c;
  // glm is column-major: m[col][row].
  glm::dmat3 m;
  m[0] = {c + k.x * k.x * C, k.y * k.x * C + k.z * s, k.z * k.x * C - k.y * s};
  m[1] = {k.x * k.y * C - k.z * s, c + k.y * k.y * C, k.z * k.y * C + k.x * s};
  m[2] = {k.x * k.z * C + k.y * s, k.y * k.z * C - k.x * s, c + k.z * k.z * C};
  return m;
}

glm::dmat3 Pose2SimCamera::rotation_matrix() const { return rodrigues(rotation); }

glm::dvec3 Pose2SimCamera::to_camera(const glm::dvec3& world) const {
  return rotation_matrix() * world + translation;
}

glm::dvec3 Pose2SimCamera::centre() const {
  return -(glm::transpose(rotation_matrix()) * translation);
}

glm::dvec2 Pose2SimCamera::project(const glm::dvec3& world) const {
  const glm::dvec3 c = to_camera(world);
  const auto& K = intrinsics.K;
  const double x = c.x / c.z, y = c.y / c.z;
  return {K[0] * x + K[1] * y + K[2], K[4] * y + K[5]};
}

std::vector<Pose2SimCamera> parse_pose2sim_calibration(std::string_view text,
                                                       const std::string& file_name) {
  if (text.find('\0') != std::string_view::npos)
    throw InputError(file_name, "binary data (a NUL byte): not a TOML calibration file");
  const std::vector<Table> tables = Parser(text, file_name).parse();
  std::vector<Pose2SimCamera> cameras;
  for (const Table& table : tables)
    if (table.name != "metadata") cameras.push_back(camera_of(table, file_name));
  if (cameras.empty())
    throw InputError(file_name, "no camera table ([cam_01] ...): not a Pose2Sim calibration");
  return cameras;
}

std::vector<Pose2SimCamera> read_pose2sim_calibration(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(name, "cannot be read: " + ec.message());
  if (bytes > kMaxFileBytes)
    throw InputError(
        name, "larger than " + std::to_string(kMaxFileBytes) + " bytes: not a calibration file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(name, "cannot be opened");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.empty()) throw InputError(name, "empty file");
  return parse_pose2sim_calibration(text, name);
}

}  // namespace mocap::camera
