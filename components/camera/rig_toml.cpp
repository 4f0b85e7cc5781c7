// The TOML side of rig_file.hpp: a parser of the TOML subset these files use (tables,
// `key = value` with strings, numbers, booleans and nested arrays that may span lines, `#`
// comments) and the writer.

#include "camera/rig_file.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "camera/rig_text.hpp"
#include "core/input_error.hpp"

namespace mocap::camera {
namespace {

constexpr int kMaxDepth = 8;  // array nesting

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

// The TOML subset of the calibration files, parsed in one pass.
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
    if (c == '\'') {  // a literal string: no escapes
      v.kind = Value::Kind::string;
      ++pos_;
      while (true) {
        if (at_end() || text_[pos_] == '\n') fail(where + "unterminated string");
        const char d = text_[pos_++];
        if (d == '\'') break;
        v.text += d;
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
  [[noreturn]] void fail_table(const std::string& what) const {
    throw InputError(file_, table_.line, "[" + table_.name + "]: " + what);
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
  double number(const std::string& key) const {
    const Value& v = get(key);
    if (v.kind != Value::Kind::number) fail(key, "expected a number");
    return v.number;
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
  // Row-major.
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
  bool is_matrix(const std::string& key) const {
    const Value& v = get(key);
    return v.kind == Value::Kind::array && !v.items.empty() &&
           v.items.front().kind == Value::Kind::array;
  }

 private:
  const Table& table_;
  const std::string& file_;
};

bool all_zero(const std::vector<double>& values) {
  for (const double v : values)
    if (v != 0.0) return false;
  return true;
}

glm::dmat3 from_row_major(const std::array<double, 9>& m) {
  glm::dmat3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[c][r] = m[static_cast<std::size_t>(3 * r + c)];
  return out;
}

Camera camera_of(const Table& table, const std::string& file) {
  const Keys keys(table, file);
  Camera cam;
  cam.name = keys.has("name") ? keys.string("name") : table.name;
  const auto size = keys.numbers("size", 2);
  if (!(size[0] >= 1 && size[1] >= 1 && size[0] <= 1e5 && size[1] <= 1e5) ||
      size[0] != std::floor(size[0]) || size[1] != std::floor(size[1]))
    keys.fail("size", "expected two positive whole numbers of pixels [width, height]");
  cam.width = static_cast<int>(size[0]);
  cam.height = static_cast<int>(size[1]);
  const auto K = keys.matrix3("matrix");
  if (!(K[0] > 0 && K[4] > 0) || K[3] != 0 || K[6] != 0 || K[7] != 0 || K[8] != 1)
    keys.fail("matrix", "expected [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0");
  if (std::abs(K[1]) > 1e-9 * K[0])
    keys.fail("matrix",
              "a skew (the 0 of the first row) is not supported: OpenCV's model has none");
  cam.fx = K[0];
  cam.cx = K[2];
  cam.fy = K[4];
  cam.cy = K[5];
  if (keys.has("fisheye")) cam.fisheye = keys.boolean("fisheye");
  cam.distortion = keys.numbers("distortions", -1);
  if (all_zero(cam.distortion)) cam.distortion.clear();
  if (keys.is_matrix("rotation")) {
    cam.rotation = from_row_major(keys.matrix3("rotation"));
    if (const std::string p = rotation_problem(cam.rotation); !p.empty())
      keys.fail("rotation", "the matrix " + p);
  } else {
    const auto r = keys.numbers("rotation", 3);
    cam.set_rodrigues({r[0], r[1], r[2]});
  }
  const auto t = keys.numbers("translation", 3);
  cam.translation = {t[0], t[1], t[2]};
  if (const std::string p = camera_problem(cam); !p.empty()) keys.fail_table("the camera " + p);
  return cam;
}

GroundPlane floor_of(const Table& table, const std::string& file) {
  const Keys keys(table, file);
  const auto n = keys.numbers("normal", 3);
  GroundPlane floor{{n[0], n[1], n[2]}, keys.number("offset")};
  if (const std::string p = ground_problem(floor); !p.empty())
    keys.fail(p.substr(0, 6), p.substr(7));  // "normal ..." or "offset ..."
  return floor;
}

// Tables that Pose2Sim does not take for cameras either.
bool camera_table(const std::string& name) {
  return name != "metadata" && !name.starts_with("metadata.") && name != "capture_volume" &&
         name != "charuco" && name != "checkerboard";
}

// Shortest text that reads back to the same double, always with a decimal point or an exponent
// (TOML tells floats from integers).
std::string array_text(const std::vector<double>& values) {
  std::string out = "[";
  for (const double v : values) {
    out += ' ';
    out += detail::real_text(v);
    out += ',';
  }
  out.back() = ']';  // the last comma, or the '[' of an empty array: "]" then
  if (values.empty()) out = "[]";
  return out;
}

}  // namespace

Rig parse_rig_toml(std::string_view text, const std::string& file_name) {
  if (text.find('\0') != std::string_view::npos)
    throw InputError(file_name, "binary data (a NUL byte): not a TOML rig file");
  const std::vector<Table> tables = Parser(text, file_name).parse();
  Rig rig;
  std::vector<long> lines;
  for (const Table& table : tables) {
    if (table.name == "metadata.floor") {
      rig.floor = floor_of(table, file_name);
    } else if (camera_table(table.name)) {
      Camera cam = camera_of(table, file_name);
      for (std::size_t i = 0; i < rig.cameras.size(); ++i)
        if (rig.cameras[i].name == cam.name)
          throw InputError(file_name, table.line,
                           "[" + table.name + "]: camera name '" + cam.name +
                               "' is also the camera of line " + std::to_string(lines[i]));
      rig.cameras.push_back(std::move(cam));
      lines.push_back(table.line);
    }
  }
  if (rig.cameras.empty())
    throw InputError(file_name, "no camera table ([cam_01] ...): not a rig or calibration file");
  return rig;
}

std::string format_rig_toml(const Rig& rig) {
  if (const std::string p = rig_problem(rig); !p.empty())
    throw std::invalid_argument("format_rig_toml: " + p);
  std::ostringstream out;
  out << "# A camera rig (docs/cameras.md): Pose2Sim/anipose calibration layout, metres.\n"
      << "# rotation: Rodrigues vector and translation: world -> camera (x_c = R x_w + t);\n"
      << "# size: [width, height] in pixels; distortions: OpenCV's coefficients.\n";
  // Tables cam_01, cam_02 ...: wide enough that anipose, which sorts the tables by name, keeps
  // the rig's order.
  const std::size_t digits = std::max<std::size_t>(2, std::to_string(rig.cameras.size()).size());
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    const Camera& c = rig.cameras[i];
    std::string table = std::to_string(i + 1);
    table.insert(0, digits - table.size(), '0');
    const glm::dvec3 r = c.rodrigues();
    // Pose2Sim and anipose pass the coefficients to OpenCV: none is written as four zeros.
    const std::vector<double> d = c.distortion.empty() ? std::vector<double>(4, 0.0) : c.distortion;
    out << "\n[cam_" << table << "]\n"
        << "name = " << detail::quoted(c.name) << "\n"
        << "size = [ " << c.width << ", " << c.height << "]\n"
        << "matrix = [ " << array_text({c.fx, 0.0, c.cx}) << ", " << array_text({0.0, c.fy, c.cy})
        << ", " << array_text({0.0, 0.0, 1.0}) << "]\n"
        << "distortions = " << array_text(d) << "\n"
        << "rotation = " << array_text({r.x, r.y, r.z}) << "\n"
        << "translation = " << array_text({c.translation.x, c.translation.y, c.translation.z})
        << "\n"
        << "fisheye = " << (c.fisheye ? "true" : "false") << "\n";
  }
  if (rig.floor) {
    const GroundPlane& f = *rig.floor;
    out << "\n# The floor in the world (mocap): points x with dot(normal, x) + offset = 0, normal "
           "up.\n"
        << "[metadata.floor]\n"
        << "normal = " << array_text({f.normal.x, f.normal.y, f.normal.z}) << "\n"
        << "offset = " << detail::real_text(f.offset) << "\n";
  }
  return out.str();
}

}  // namespace mocap::camera
