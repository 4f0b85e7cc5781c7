#include "io/npz.hpp"

#include <cctype>
#include <map>

#include "core/input_error.hpp"
#include "io/byte_reader.hpp"
#include "io/read_file.hpp"

namespace mocap::io {
namespace {

constexpr std::string_view kMagic = "\x93NUMPY";
constexpr std::size_t kMaxHeaderBytes = 1u << 20;  // NumPy itself writes a few hundred bytes

// A value of the header dict: a string, a bool or a tuple of integers.
struct HeaderValue {
  enum class Type { string, boolean, tuple } type = Type::string;
  std::string text;
  bool flag = false;
  std::vector<std::size_t> numbers;
};

// Parses the Python dict literal of a .npy header; only what NumPy writes is accepted.
class HeaderParser {
 public:
  HeaderParser(std::string_view text, const std::string& source) : text_(text), source_(source) {}

  std::map<std::string, HeaderValue> parse() {
    std::map<std::string, HeaderValue> out;
    expect('{');
    while (!accept('}')) {
      const std::string key = string_literal();
      expect(':');
      out[key] = value();
      if (!accept(',')) {
        expect('}');
        break;
      }
    }
    skip_space();
    if (pos_ != text_.size()) fail("text after the closing brace");
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(source_, ".npy header, character " + std::to_string(pos_) + ": " + what +
                                  " in " + std::string(text_.substr(0, 200)));
  }
  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  bool accept(char c) {
    skip_space();
    if (pos_ < text_.size() && text_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  void expect(char c) {
    if (!accept(c)) fail(std::string("expected '") + c + "'");
  }
  bool accept_word(std::string_view word) {
    skip_space();
    if (text_.substr(pos_, word.size()) != word) return false;
    pos_ += word.size();
    return true;
  }
  std::string string_literal() {
    skip_space();
    if (pos_ >= text_.size() || (text_[pos_] != '\'' && text_[pos_] != '"'))
      fail("expected a string");
    const char quote = text_[pos_++];
    const std::size_t end = text_.find(quote, pos_);
    if (end == std::string_view::npos) fail("unterminated string");
    std::string s(text_.substr(pos_, end - pos_));
    pos_ = end + 1;
    return s;
  }
  std::size_t integer() {
    skip_space();
    std::size_t value = 0, digits = 0;
    while (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_]))) {
      if (++digits > 18) fail("dimension too large");
      value = value * 10 + static_cast<std::size_t>(text_[pos_++] - '0');
    }
    if (digits == 0) fail("expected a dimension");
    accept('L');  // Python 2 long suffix
    return value;
  }
  HeaderValue value() {
    HeaderValue v;
    skip_space();
    if (accept_word("True")) {
      v.type = HeaderValue::Type::boolean;
      v.flag = true;
    } else if (accept_word("False")) {
      v.type = HeaderValue::Type::boolean;
    } else if (accept('(')) {
      v.type = HeaderValue::Type::tuple;
      while (!accept(')')) {
        v.numbers.push_back(integer());
        if (!accept(',')) {
          expect(')');
          break;
        }
      }
    } else {
      v.text = string_literal();
    }
    return v;
  }

  std::string_view text_;
  const std::string& source_;
  std::size_t pos_ = 0;
};

struct Header {
  DType dtype = DType::float64;
  char byte_order = '|';
  bool fortran_order = false;
  std::vector<std::size_t> shape;
};

Header interpret(const std::map<std::string, HeaderValue>& dict, const std::string& source) {
  const auto get = [&](const char* key, HeaderValue::Type type) -> const HeaderValue& {
    const auto it = dict.find(key);
    if (it == dict.end() || it->second.type != type) {
      throw InputError(source, std::string(".npy header has no valid '") + key + "'");
    }
    return it->second;
  };
  Header h;
  std::string descr = get("descr", HeaderValue::Type::string).text;
  if (!descr.empty() && std::string_view("<>|=").find(descr[0]) != std::string_view::npos) {
    h.byte_order = descr[0];
    descr.erase(0, 1);
  }
  if (!parse_dtype_code(descr, h.dtype)) {
    throw InputError(source, "dtype '" + get("descr", HeaderValue::Type::string).text +
                                 "' is not supported (numbers, bool and objects are)");
  }
  h.fortran_order = get("fortran_order", HeaderValue::Type::boolean).flag;
  h.shape = get("shape", HeaderValue::Type::tuple).numbers;
  return h;
}

std::string_view read_header_text(ByteReader& r) {
  if (r.bytes(kMagic.size()) != kMagic) r.fail("not a .npy file (no \\x93NUMPY magic)");
  const std::uint8_t major = r.u8();
  r.u8();  // minor
  if (major < 1 || major > 3) r.fail(".npy version " + std::to_string(major) + " is not supported");
  const std::uint32_t length = major == 1 ? r.u16() : r.u32();
  if (length > kMaxHeaderBytes) r.fail(".npy header of " + std::to_string(length) + " bytes");
  return r.bytes(length);
}

}  // namespace

NpyContent parse_npy(std::string_view bytes, const std::string& source, const NpyLimits& limits) {
  ByteReader r(bytes, source);
  const Header h = interpret(HeaderParser(read_header_text(r), source).parse(), source);
  NpyContent out;
  out.array.dtype = h.dtype;
  out.array.shape = h.shape;
  const std::string_view payload = r.bytes(r.remaining());
  if (h.dtype == DType::object) {
    out.objects = Pickle::parse(payload, source + " (pickled object array)", limits.pickle);
    const Pickle::Value root = out.objects->root();
    if (root.kind() != Pickle::Kind::array || root.array().shape != h.shape) {
      throw InputError(source, "the pickled object array does not match the .npy header");
    }
  } else {
    set_array_data(out.array, payload, h.byte_order, h.fortran_order, source);
  }
  return out;
}

NpyContent read_npy(const std::filesystem::path& file, const NpyLimits& limits) {
  return parse_npy(read_whole_file(file, limits.zip.max_member_bytes), file.string(), limits);
}

NpzFile NpzFile::open(const std::filesystem::path& file, const NpyLimits& limits) {
  return NpzFile(ZipArchive::open(file, limits.zip), limits);
}

NpzFile NpzFile::from_bytes(std::string bytes, std::string source, const NpyLimits& limits) {
  return NpzFile(ZipArchive::from_bytes(std::move(bytes), std::move(source), limits.zip), limits);
}

std::vector<std::string> NpzFile::keys() const {
  std::vector<std::string> out;
  for (const auto& m : zip_.members()) {
    std::string name = m.name;
    if (name.size() > 4 && name.ends_with(".npy")) name.resize(name.size() - 4);
    out.push_back(std::move(name));
  }
  return out;
}

bool NpzFile::contains(std::string_view key) const {
  return zip_.find(std::string(key) + ".npy") != nullptr || zip_.find(key) != nullptr;
}

NpyContent NpzFile::read(std::string_view key) const {
  const ZipMember* m = zip_.find(std::string(key) + ".npy");
  if (m == nullptr) m = zip_.find(key);
  if (m == nullptr) {
    std::string known;
    for (const auto& k : keys()) known += (known.empty() ? "" : ", ") + k;
    throw InputError(zip_.source(), "no array '" + std::string(key) + "' (has: " + known + ")");
  }
  return parse_npy(zip_.extract(*m), zip_.source() + ":" + m->name, limits_);
}

}  // namespace mocap::io
