#pragma once
// A safe reader for the small part of Python's pickle format that NumPy uses to store object
// arrays (np.save / np.savez with allow_pickle): None, bools, ints, floats, str, bytes, lists,
// tuples, dicts and NumPy arrays and dtypes. It is not an interpreter: the only "globals" it
// accepts are NumPy's array reconstruction (numpy.core.multiarray._reconstruct, numpy.ndarray,
// numpy.dtype, numpy.core.multiarray.scalar, and numpy.core.numeric._frombuffer for protocol 5;
// also under NumPy 2's numpy._core) and _codecs.encode (how protocol 2 stores bytes); any other
// global, opcode or shape is an InputError. Protocols 2 to 5 are read.
//
// Robustness: every length is checked against the input before use, the number of values and
// the stack depth are capped, values live in one flat table (no recursion while reading or
// destroying, so self-referencing or deeply nested input cannot overflow the stack).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/ndarray.hpp"

namespace mocap::io {

struct PickleLimits {
  std::size_t max_values = 1u << 20;  // values created while reading (each costs ~100 bytes)
  std::size_t max_stack = 1u << 16;   // depth of the pickle machine's stack
};

class Pickle {
 public:
  // `other`: a NumPy dtype or a global that reading left on the way (not data).
  enum class Kind : std::uint8_t {
    none,
    boolean,
    integer,
    real,
    string,
    bytes,
    list,
    tuple,
    dict,
    array,
    other
  };

  // A handle to one value of a Pickle (valid while that Pickle object lives and is not moved
  // from). Asking a value for the
  // wrong kind throws InputError naming the pickle's source, so callers can read nested data
  // without checking every step themselves.
  class Value {
   public:
    Kind kind() const;
    bool as_bool() const;
    std::int64_t as_int() const;
    double as_real() const;                // integers are converted
    const std::string& as_string() const;  // str (UTF-8) or bytes
    // Elements of a list or tuple, or of an object array (C order).
    std::size_t size() const;
    Value operator[](std::size_t i) const;
    // Dict entries in insertion order (a key assigned twice keeps its first place, last value).
    std::size_t dict_size() const;
    Value key(std::size_t i) const;
    Value value(std::size_t i) const;
    std::optional<Value> find(std::string_view key) const;  // a str key
    Value at(std::string_view key) const;                   // find() or InputError
    // NumPy arrays. item(): the one element of a 0-d object array (NumPy's .item()).
    const NdArray& array() const;
    Value item() const;

   private:
    friend class Pickle;
    Value(const Pickle* pickle, std::uint32_t id) : pickle_(pickle), id_(id) {}
    [[noreturn]] void wrong_kind(std::string_view wanted) const;
    const Pickle* pickle_;
    std::uint32_t id_;
  };

  // Reads one pickle; `source` names the input in messages. Throws InputError.
  static Pickle parse(std::string_view bytes, std::string source, const PickleLimits& limits = {});

  Pickle(Pickle&&) noexcept;
  Pickle& operator=(Pickle&&) noexcept;
  ~Pickle();

  Value root() const { return Value(this, root_); }
  const std::string& source() const { return source_; }

 private:
  friend class PickleMachine;
  struct Node;
  Pickle() = default;

  std::string source_;
  std::vector<Node> nodes_;
  std::vector<NdArray> arrays_;
  std::uint32_t root_ = 0;
};

std::string_view to_string(Pickle::Kind kind);

}  // namespace mocap::io
