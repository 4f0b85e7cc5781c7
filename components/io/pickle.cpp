#include "io/pickle.hpp"

#include <unordered_map>

#include "core/input_error.hpp"
#include "io/byte_reader.hpp"

namespace mocap::io {

// One value. Containers hold the ids of their elements (dicts: key, value, key, value, ...), so
// sharing (memo) and even cycles are just ids, and nothing is ever destroyed recursively.
struct Pickle::Node {
  Kind kind = Kind::none;
  bool flag = false;         // boolean; arrays: built; dtype: is a dtype
  std::int64_t integer = 0;  // integer; arrays: index into arrays_; dtype: DType
  double real = 0.0;
  std::string text;  // string, bytes; globals: "module.name"; dtype: byte order
  std::vector<std::uint32_t> items;
};

namespace {

using Kind = Pickle::Kind;

// The globals a NumPy pickle may name, and what they become.
enum class Callable { none, reconstruct, ndarray, dtype, scalar, encode, frombuffer };

Callable callable_named(std::string_view module, std::string_view name) {
  const bool multiarray = module == "numpy.core.multiarray" || module == "numpy._core.multiarray";
  if (multiarray && name == "_reconstruct") return Callable::reconstruct;
  if (multiarray && name == "scalar") return Callable::scalar;
  if (module == "numpy" && name == "ndarray") return Callable::ndarray;
  if (module == "numpy" && name == "dtype") return Callable::dtype;
  if (module == "_codecs" && name == "encode") return Callable::encode;
  // Protocol 5: ndarray.__reduce_ex__ passes the data as a buffer to numeric._frombuffer.
  const bool numeric = module == "numpy.core.numeric" || module == "numpy._core.numeric";
  if (numeric && name == "_frombuffer") return Callable::frombuffer;
  return Callable::none;
}

// UTF-8 → Latin-1 bytes, as _codecs.encode(s, 'latin1') does; false if a code point is > 255.
bool utf8_to_latin1(std::string_view in, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    const auto c = static_cast<unsigned char>(in[i]);
    if (c < 0x80) {
      out.push_back(static_cast<char>(c));
    } else if ((c & 0xe0) == 0xc0 && c <= 0xc3 && i + 1 < in.size()) {
      const auto next = static_cast<unsigned char>(in[++i]);
      if ((next & 0xc0) != 0x80) return false;
      out.push_back(static_cast<char>(((c & 0x03) << 6) | (next & 0x3f)));
    } else {
      return false;
    }
  }
  return true;
}

}  // namespace

// The pickle virtual machine, restricted to the opcodes and globals listed in pickle.hpp.
class PickleMachine {
 public:
  PickleMachine(std::string_view bytes, Pickle& out, const PickleLimits& limits)
      : in_(bytes, out.source_), out_(out), limits_(limits) {}

  void run() {
    for (;;) {
      const std::size_t at = in_.position();
      if (in_.at_end()) in_.fail("pickle ends without STOP (truncated?)");
      const auto op = static_cast<unsigned char>(in_.bytes(1)[0]);
      if (op == '.') break;
      step(op, at);
    }
    if (stack_.size() != 1 || !marks_.empty()) in_.fail("STOP with a malformed stack");
    out_.root_ = stack_.back();
    merge_dict_keys();
  }

 private:
  using Node = Pickle::Node;

  [[noreturn]] void fail(std::size_t at, const std::string& what) const {
    throw InputError(out_.source_, "pickle byte " + std::to_string(at) + ": " + what);
  }

  std::uint32_t add(Node node) {
    if (out_.nodes_.size() >= limits_.max_values) {
      in_.fail("more than " + std::to_string(limits_.max_values) + " values (limit)");
    }
    out_.nodes_.push_back(std::move(node));
    return static_cast<std::uint32_t>(out_.nodes_.size() - 1);
  }
  std::uint32_t add(Kind kind) {
    Node n;
    n.kind = kind;
    return add(std::move(n));
  }
  std::uint32_t add_integer(std::int64_t value) {
    Node n;
    n.kind = Kind::integer;
    n.integer = value;
    return add(std::move(n));
  }
  std::uint32_t add_text(Kind kind, std::string_view text) {
    Node n;
    n.kind = kind;
    n.text = std::string(text);
    return add(std::move(n));
  }

  void push(std::uint32_t id) {
    if (stack_.size() >= limits_.max_stack) {
      in_.fail("stack deeper than " + std::to_string(limits_.max_stack) + " (limit)");
    }
    stack_.push_back(id);
  }
  std::uint32_t pop(std::size_t at) {
    if (stack_.size() <= floor()) fail(at, "stack underflow");
    const std::uint32_t id = stack_.back();
    stack_.pop_back();
    return id;
  }
  std::uint32_t top(std::size_t at) const {
    if (stack_.size() <= floor()) fail(at, "stack underflow");
    return stack_.back();
  }
  // Values below the innermost mark belong to an outer construct.
  std::size_t floor() const { return marks_.empty() ? 0 : marks_.back(); }
  std::vector<std::uint32_t> pop_to_mark(std::size_t at) {
    if (marks_.empty()) fail(at, "no MARK");
    const std::size_t begin = marks_.back();
    marks_.pop_back();
    std::vector<std::uint32_t> items(stack_.begin() + static_cast<std::ptrdiff_t>(begin),
                                     stack_.end());
    stack_.resize(begin);
    return items;
  }
  Node& node(std::uint32_t id) { return out_.nodes_[id]; }

  Node& expect(std::uint32_t id, Kind kind, std::size_t at, std::string_view what) {
    Node& n = node(id);
    if (n.kind != kind) {
      fail(at, std::string(what) + ": expected " + std::string(to_string(kind)) + ", found " +
                   std::string(to_string(n.kind)));
    }
    return n;
  }

  void memo_put(std::uint32_t index, std::size_t at) { memo_[index] = top(at); }
  void memo_get(std::uint32_t index, std::size_t at) {
    const auto it = memo_.find(index);
    if (it == memo_.end()) fail(at, "memo entry " + std::to_string(index) + " was never stored");
    push(it->second);
  }

  std::uint32_t tuple_of(std::vector<std::uint32_t> items) {
    Node n;
    n.kind = Kind::tuple;
    n.items = std::move(items);
    return add(std::move(n));
  }

  void step(unsigned char op, std::size_t at) {
    if (push_constant(op, at) || push_text(op, at) || build_container(op, at) || use_memo(op, at) ||
        call_numpy(op, at) || manage_stack(op, at)) {
      return;
    }
    fail(at, "opcode 0x" + hex(op) + " is not supported by this reader");
  }

  static std::string hex(unsigned char op) {
    constexpr char digits[] = "0123456789abcdef";
    return {digits[op >> 4], digits[op & 15]};
  }

  bool push_constant(unsigned char op, std::size_t at) {
    switch (op) {
      case 'N':
        push(add(Kind::none));
        return true;
      case 0x88:
      case 0x89: {
        Node n;
        n.kind = Kind::boolean;
        n.flag = op == 0x88;
        push(add(std::move(n)));
        return true;
      }
      case 'J':
        push(add_integer(in_.i32()));
        return true;
      case 'K':
        push(add_integer(in_.u8()));
        return true;
      case 'M':
        push(add_integer(in_.u16()));
        return true;
      case 0x8a:
        push(add_integer(read_long1(at)));
        return true;
      case 'G': {
        Node n;
        n.kind = Kind::real;
        n.real = in_.f64_big_endian();
        push(add(std::move(n)));
        return true;
      }
      default:
        return false;
    }
  }

  // LONG1: n little-endian two's-complement bytes; only values that fit 64 bits are accepted.
  std::int64_t read_long1(std::size_t at) {
    const std::uint8_t n = in_.u8();
    if (n > 8) fail(at, "integer of " + std::to_string(n) + " bytes is too large");
    const std::string_view b = in_.bytes(n);
    std::uint64_t bits = 0;
    for (std::size_t i = n; i-- > 0;) bits = (bits << 8) | static_cast<std::uint8_t>(b[i]);
    if (n > 0 && n < 8 && (static_cast<std::uint8_t>(b[n - 1]) & 0x80)) {
      bits |= ~std::uint64_t{0} << (8 * n);  // sign-extend
    }
    return static_cast<std::int64_t>(bits);
  }

  bool push_text(unsigned char op, std::size_t) {
    switch (op) {
      case 'X':
        push(add_text(Kind::string, in_.bytes(in_.u32())));
        return true;
      case 0x8c:
        push(add_text(Kind::string, in_.bytes(in_.u8())));
        return true;
      case 0x8d:
        push(add_text(Kind::string, in_.bytes(in_.u64())));
        return true;
      case 'C':
        push(add_text(Kind::bytes, in_.bytes(in_.u8())));
        return true;
      case 'B':
        push(add_text(Kind::bytes, in_.bytes(in_.u32())));
        return true;
      case 0x8e:
      case 0x96:  // BYTEARRAY8: a protocol 5 in-band buffer, read as bytes
        push(add_text(Kind::bytes, in_.bytes(in_.u64())));
        return true;
      default:
        return false;
    }
  }

  bool build_container(unsigned char op, std::size_t at) {
    switch (op) {
      case ']':
        push(add(Kind::list));
        return true;
      case '}':
        push(add(Kind::dict));
        return true;
      case ')':
        push(tuple_of({}));
        return true;
      case 0x85:
      case 0x86:
      case 0x87: {
        std::vector<std::uint32_t> items(op - 0x84);
        for (std::size_t i = items.size(); i-- > 0;) items[i] = pop(at);
        push(tuple_of(std::move(items)));
        return true;
      }
      case 't':
        push(tuple_of(pop_to_mark(at)));
        return true;
      case 'l':
      case 'd': {
        Node n;
        n.kind = op == 'l' ? Kind::list : Kind::dict;
        n.items = pop_to_mark(at);
        if (n.kind == Kind::dict && n.items.size() % 2 != 0) fail(at, "DICT with an odd count");
        push(add(std::move(n)));
        return true;
      }
      case 'a':
      case 'e':
        append(op == 'a' ? std::vector<std::uint32_t>{pop(at)} : pop_to_mark(at), at);
        return true;
      case 's':
      case 'u':
        set_items(op == 's' ? pop_pair(at) : pop_to_mark(at), at);
        return true;
      default:
        return false;
    }
  }

  std::vector<std::uint32_t> pop_pair(std::size_t at) {
    const std::uint32_t value = pop(at), key = pop(at);
    return {key, value};
  }

  void append(std::vector<std::uint32_t> items, std::size_t at) {
    Node& list = expect(top(at), Kind::list, at, "APPEND");
    list.items.insert(list.items.end(), items.begin(), items.end());
  }

  void set_items(std::vector<std::uint32_t> items, std::size_t at) {
    if (items.size() % 2 != 0) fail(at, "SETITEMS with an odd count");
    Node& dict = expect(top(at), Kind::dict, at, "SETITEM");
    dict.items.insert(dict.items.end(), items.begin(), items.end());
  }

  bool use_memo(unsigned char op, std::size_t at) {
    switch (op) {
      case 'q':
        memo_put(in_.u8(), at);
        return true;
      case 'r':
        memo_put(in_.u32(), at);
        return true;
      case 0x94:
        memo_put(static_cast<std::uint32_t>(memo_.size()), at);
        return true;
      case 'h':
        memo_get(in_.u8(), at);
        return true;
      case 'j':
        memo_get(in_.u32(), at);
        return true;
      default:
        return false;
    }
  }

  bool manage_stack(unsigned char op, std::size_t at) {
    switch (op) {
      case 0x80:
        if (const std::uint8_t protocol = in_.u8(); protocol < 2 || protocol > 5) {
          fail(at, "pickle protocol " + std::to_string(protocol) + " is not supported");
        }
        return true;
      case 0x95:
        in_.skip(8);  // FRAME: a length hint for buffered readers
        return true;
      case '(':
        if (marks_.size() >= limits_.max_stack) in_.fail("too many nested MARKs (limit)");
        marks_.push_back(stack_.size());
        return true;
      case '0':
        pop(at);
        return true;
      case '1':
        pop_to_mark(at);
        return true;
      case '2':
        push(top(at));
        return true;
      default:
        return false;
    }
  }

  bool call_numpy(unsigned char op, std::size_t at) {
    switch (op) {
      case 'c': {
        const std::string module = read_line(at), name = read_line(at);
        push_global(module, name, at);
        return true;
      }
      case 0x93: {
        const std::uint32_t name = pop(at), module = pop(at);
        push_global(expect(module, Kind::string, at, "STACK_GLOBAL").text,
                    expect(name, Kind::string, at, "STACK_GLOBAL").text, at);
        return true;
      }
      case 'R': {
        const std::uint32_t args = pop(at), callable = pop(at);
        push(reduce(callable, args, at));
        return true;
      }
      case 'b': {
        const std::uint32_t state = pop(at);
        build(top(at), state, at);
        return true;
      }
      default:
        return false;
    }
  }

  std::string read_line(std::size_t at) {
    std::string line;
    for (;;) {
      const char c = in_.bytes(1)[0];
      if (c == '\n') return line;
      if (line.size() >= 200) fail(at, "GLOBAL name too long");
      line.push_back(c);
    }
  }

  void push_global(const std::string& module, const std::string& name, std::size_t at) {
    const Callable callable = callable_named(module, name);
    if (callable == Callable::none) {
      fail(at, "refuses global " + module + "." + name +
                   " (only NumPy arrays and plain Python values are read)");
    }
    Node n;
    n.kind = Kind::other;
    n.integer = static_cast<std::int64_t>(callable);
    n.text = module + "." + name;
    push(add(std::move(n)));
  }

  Callable callable_of(std::uint32_t id) const {
    const Node& n = out_.nodes_[id];
    return n.kind == Kind::other && !n.flag ? static_cast<Callable>(n.integer) : Callable::none;
  }

  const Node& argument(const Node& args, std::size_t i, Kind kind, std::size_t at,
                       std::string_view what) {
    if (i >= args.items.size()) fail(at, std::string(what) + ": too few arguments");
    return expect(args.items[i], kind, at, what);
  }

  std::uint32_t reduce(std::uint32_t callable_id, std::uint32_t args_id, std::size_t at) {
    const Node& args = expect(args_id, Kind::tuple, at, "REDUCE arguments");
    switch (callable_of(callable_id)) {
      case Callable::reconstruct:
        if (args.items.empty() || callable_of(args.items[0]) != Callable::ndarray) {
          fail(at, "_reconstruct of something other than numpy.ndarray");
        }
        return new_array();
      case Callable::dtype:
        return new_dtype(argument(args, 0, Kind::string, at, "numpy.dtype").text, at);
      case Callable::scalar:
        return new_scalar(args, at);
      case Callable::encode:
        return encode_latin1(argument(args, 0, Kind::string, at, "_codecs.encode").text, at);
      case Callable::frombuffer:
        return array_from_buffer(args, at);
      default:
        fail(at, "REDUCE of something that is not an accepted NumPy callable");
    }
  }

  std::uint32_t new_array() {
    Node n;
    n.kind = Kind::array;
    n.integer = static_cast<std::int64_t>(out_.arrays_.size());
    out_.arrays_.emplace_back();
    return add(std::move(n));
  }

  std::uint32_t new_dtype(const std::string& code, std::size_t at) {
    DType dtype;
    if (!parse_dtype_code(code, dtype)) fail(at, "dtype '" + code + "' is not supported");
    Node n;
    n.kind = Kind::other;
    n.flag = true;  // a dtype, not a callable
    n.integer = static_cast<std::int64_t>(dtype);
    n.text = "=";  // byte order until BUILD says otherwise
    return add(std::move(n));
  }

  const Node& expect_dtype(std::uint32_t id, std::size_t at) {
    const Node& n = node(id);
    if (n.kind != Kind::other || !n.flag) fail(at, "expected a numpy.dtype");
    return n;
  }

  // numpy.core.multiarray.scalar(dtype, bytes): one number, stored as int or real.
  std::uint32_t new_scalar(const Node& args, std::size_t at) {
    if (args.items.size() != 2) fail(at, "numpy scalar needs (dtype, bytes)");
    const Node& dt = expect_dtype(args.items[0], at);
    NdArray one;
    one.dtype = static_cast<DType>(dt.integer);
    if (one.dtype == DType::object) fail(at, "object scalar");
    const Node& raw = expect(args.items[1], Kind::bytes, at, "numpy scalar");
    set_array_data(one, raw.text, dt.text[0], false, out_.source_);
    const double value = one.to_doubles()[0];
    const bool is_integer = one.dtype != DType::float32 && one.dtype != DType::float64;
    if (is_integer && one.dtype != DType::uint64)
      return add_integer(static_cast<std::int64_t>(value));
    Node n;
    n.kind = Kind::real;
    n.real = value;
    return add(std::move(n));
  }

  // numpy.core.numeric._frombuffer(buffer, dtype, shape, order) with order 'C' or 'F'.
  std::uint32_t array_from_buffer(const Node& args, std::size_t at) {
    if (args.items.size() != 4) fail(at, "_frombuffer needs (buffer, dtype, shape, order)");
    const Node& order = expect(args.items[3], Kind::string, at, "_frombuffer order");
    if (order.text != "C" && order.text != "F") fail(at, "_frombuffer order '" + order.text + "'");
    const bool fortran = order.text == "F";
    const Node dtype = expect_dtype(args.items[1], at);
    NdArray a;
    a.dtype = static_cast<DType>(dtype.integer);
    if (a.dtype == DType::object) fail(at, "_frombuffer of objects");
    a.shape = read_shape(expect(args.items[2], Kind::tuple, at, "_frombuffer shape"), at);
    set_array_data(a, expect(args.items[0], Kind::bytes, at, "_frombuffer buffer").text,
                   dtype.text[0], fortran, out_.source_);
    const std::uint32_t id = new_array();
    out_.arrays_.back() = std::move(a);
    node(id).flag = true;
    return id;
  }

  std::uint32_t encode_latin1(const std::string& text, std::size_t at) {
    std::string bytes;
    if (!utf8_to_latin1(text, bytes)) fail(at, "_codecs.encode of a non-Latin-1 string");
    return add_text(Kind::bytes, bytes);
  }

  void build(std::uint32_t target, std::uint32_t state, std::size_t at) {
    Node& t = node(target);
    if (t.kind == Kind::other && t.flag) return build_dtype(t, state, at);
    if (t.kind == Kind::array) return build_array(t, state, at);
    fail(at, "BUILD of a " + std::string(to_string(t.kind)) + " is not supported");
  }

  // dtype state: (version, byte order, subarray, names, fields, elsize, alignment, flags).
  void build_dtype(Node& dtype, std::uint32_t state_id, std::size_t at) {
    const Node& state = expect(state_id, Kind::tuple, at, "dtype state");
    const std::string& order = argument(state, 1, Kind::string, at, "dtype byte order").text;
    if (order.size() != 1 || std::string_view("<>|=").find(order[0]) == std::string_view::npos) {
      fail(at, "dtype byte order '" + order + "'");
    }
    dtype.text = order;
  }

  // ndarray state: (version, shape, dtype, is_fortran, data); data is bytes, or a list of
  // values for object arrays.
  void build_array(Node& array_node, std::uint32_t state_id, std::size_t at) {
    if (array_node.flag) fail(at, "array built twice");
    const Node state = expect(state_id, Kind::tuple, at, "array state");  // copy: add() may move
    if (state.items.size() != 5) fail(at, "array state is not a 5-tuple");
    NdArray& a = out_.arrays_[static_cast<std::size_t>(array_node.integer)];
    a.shape = read_shape(argument(state, 1, Kind::tuple, at, "array shape"), at);
    const Node dtype = expect_dtype(state.items[2], at);
    const bool fortran = argument(state, 3, Kind::boolean, at, "array order").flag;
    a.dtype = static_cast<DType>(dtype.integer);
    const Node& data = node(state.items[4]);
    std::size_t count = 0;
    if (!element_count(a.shape, count)) fail(at, "array shape overflows");
    if (a.dtype == DType::object) {
      if (data.kind != Kind::list || data.items.size() != count) {
        fail(at, "object array of " + std::to_string(count) + " elements has no matching list");
      }
      array_node.items = data.items;  // C order for a 0-d or 1-d object array
    } else {
      if (data.kind != Kind::bytes) fail(at, "array data is not bytes");
      set_array_data(a, data.text, dtype.text[0], fortran, out_.source_);
    }
    array_node.flag = true;
  }

  std::vector<std::size_t> read_shape(const Node& tuple, std::size_t at) {
    std::vector<std::size_t> shape;
    for (std::uint32_t id : tuple.items) {
      const Node& d = expect(id, Kind::integer, at, "array dimension");
      if (d.integer < 0) fail(at, "negative array dimension");
      shape.push_back(static_cast<std::size_t>(d.integer));
    }
    return shape;
  }

  // Python keeps one entry per key (first position, last value); SETITEMs were appended
  // blindly while reading (no quadratic search), so merge str and int keys once here.
  void merge_dict_keys() {
    for (Node& n : out_.nodes_) {
      if (n.kind != Kind::dict || n.items.size() <= 2) continue;
      std::unordered_map<std::string, std::size_t> first;
      std::vector<std::uint32_t> merged;
      for (std::size_t i = 0; i < n.items.size(); i += 2) {
        const Node& key = out_.nodes_[n.items[i]];
        // A one-letter kind tag keeps the str "1" and the int 1 apart.
        std::string hash;
        if (key.kind == Kind::string) hash.append(1, 's').append(key.text);
        if (key.kind == Kind::integer) hash.append(1, 'i').append(std::to_string(key.integer));
        const auto [it, fresh] = first.try_emplace(hash, merged.size());
        if (hash.empty() || fresh) {
          merged.push_back(n.items[i]);
          merged.push_back(n.items[i + 1]);
        } else {
          merged[it->second + 1] = n.items[i + 1];
        }
      }
      n.items = std::move(merged);
    }
  }

  ByteReader in_;
  Pickle& out_;
  const PickleLimits& limits_;
  std::vector<std::uint32_t> stack_;
  std::vector<std::size_t> marks_;
  std::unordered_map<std::uint32_t, std::uint32_t> memo_;
};

Pickle::Pickle(Pickle&&) noexcept = default;
Pickle& Pickle::operator=(Pickle&&) noexcept = default;
Pickle::~Pickle() = default;

Pickle Pickle::parse(std::string_view bytes, std::string source, const PickleLimits& limits) {
  Pickle p;
  p.source_ = std::move(source);
  PickleMachine(bytes, p, limits).run();
  return p;
}

// ---- Value -----------------------------------------------------------------------------------

Pickle::Kind Pickle::Value::kind() const { return pickle_->nodes_[id_].kind; }

void Pickle::Value::wrong_kind(std::string_view wanted) const {
  throw InputError(pickle_->source_,
                   "expected " + std::string(wanted) + ", found " + std::string(to_string(kind())));
}

bool Pickle::Value::as_bool() const {
  if (kind() != Kind::boolean) wrong_kind("a bool");
  return pickle_->nodes_[id_].flag;
}

std::int64_t Pickle::Value::as_int() const {
  if (kind() != Kind::integer) wrong_kind("an int");
  return pickle_->nodes_[id_].integer;
}

double Pickle::Value::as_real() const {
  if (kind() == Kind::integer) return static_cast<double>(pickle_->nodes_[id_].integer);
  if (kind() != Kind::real) wrong_kind("a float");
  return pickle_->nodes_[id_].real;
}

const std::string& Pickle::Value::as_string() const {
  if (kind() != Kind::string && kind() != Kind::bytes) wrong_kind("a str");
  return pickle_->nodes_[id_].text;
}

std::size_t Pickle::Value::size() const {
  const Node& n = pickle_->nodes_[id_];
  if (n.kind != Kind::list && n.kind != Kind::tuple && n.kind != Kind::array) {
    wrong_kind("a list, tuple or array");
  }
  return n.items.size();
}

Pickle::Value Pickle::Value::operator[](std::size_t i) const {
  if (i >= size()) {
    throw InputError(pickle_->source_, "index " + std::to_string(i) + " out of range (size " +
                                           std::to_string(size()) + ")");
  }
  return Value(pickle_, pickle_->nodes_[id_].items[i]);
}

std::size_t Pickle::Value::dict_size() const {
  if (kind() != Kind::dict) wrong_kind("a dict");
  return pickle_->nodes_[id_].items.size() / 2;
}

Pickle::Value Pickle::Value::key(std::size_t i) const {
  if (i >= dict_size()) throw InputError(pickle_->source_, "dict entry out of range");
  return Value(pickle_, pickle_->nodes_[id_].items[2 * i]);
}

Pickle::Value Pickle::Value::value(std::size_t i) const {
  if (i >= dict_size()) throw InputError(pickle_->source_, "dict entry out of range");
  return Value(pickle_, pickle_->nodes_[id_].items[2 * i + 1]);
}

std::optional<Pickle::Value> Pickle::Value::find(std::string_view wanted) const {
  for (std::size_t i = 0; i < dict_size(); ++i) {
    const Value k = key(i);
    if (k.kind() == Kind::string && k.as_string() == wanted) return value(i);
  }
  return std::nullopt;
}

Pickle::Value Pickle::Value::at(std::string_view wanted) const {
  if (auto v = find(wanted)) return *v;
  throw InputError(pickle_->source_, "no key '" + std::string(wanted) + "'");
}

const NdArray& Pickle::Value::array() const {
  const Node& n = pickle_->nodes_[id_];
  if (n.kind != Kind::array) wrong_kind("a NumPy array");
  if (!n.flag) throw InputError(pickle_->source_, "NumPy array without data (no BUILD)");
  return pickle_->arrays_[static_cast<std::size_t>(n.integer)];
}

Pickle::Value Pickle::Value::item() const {
  const NdArray& a = array();
  if (a.dtype != DType::object || a.count() != 1) {
    throw InputError(pickle_->source_, "item() needs an object array of one element");
  }
  return (*this)[0];
}

std::string_view to_string(Pickle::Kind kind) {
  switch (kind) {
    case Pickle::Kind::none:
      return "None";
    case Pickle::Kind::boolean:
      return "bool";
    case Pickle::Kind::integer:
      return "int";
    case Pickle::Kind::real:
      return "float";
    case Pickle::Kind::string:
      return "str";
    case Pickle::Kind::bytes:
      return "bytes";
    case Pickle::Kind::list:
      return "list";
    case Pickle::Kind::tuple:
      return "tuple";
    case Pickle::Kind::dict:
      return "dict";
    case Pickle::Kind::array:
      return "ndarray";
    case Pickle::Kind::other:
      return "NumPy helper";
  }
  return "?";
}

}  // namespace mocap::io
