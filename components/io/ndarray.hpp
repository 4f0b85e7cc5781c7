#pragma once
// A NumPy array as read from .npy files and pickles: element type, shape and the raw elements in
// C order and native byte order. Only plain numeric dtypes (and object arrays, whose elements
// live in a Pickle) are supported.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::io {

enum class DType : std::uint8_t {
  boolean,
  int8,
  uint8,
  int16,
  uint16,
  int32,
  uint32,
  int64,
  uint64,
  float32,
  float64,
  object,
};

std::size_t item_size(DType dtype);  // bytes per element; object: 8 (a pointer in NumPy)
std::string_view to_string(DType dtype);

// A dtype descriptor without its byte-order character ("f4", "u1", "b1", "O", "O8", "float32"
// is not accepted). Returns false for anything else (strings, structured dtypes, complex...).
bool parse_dtype_code(std::string_view code, DType& out);

struct NdArray {
  DType dtype = DType::float64;
  std::vector<std::size_t> shape;
  std::string data;  // count() * item_size bytes, C order, native byte order; empty for objects

  std::size_t count() const;  // product of the shape (1 for a 0-d array)
  // Every element converted to the wanted type; throws std::invalid_argument for object arrays.
  std::vector<double> to_doubles() const;
  std::vector<float> to_floats() const;
};

// The number of elements of `shape`; false when the product (times 8 bytes) would overflow.
bool element_count(const std::vector<std::size_t>& shape, std::size_t& count);

// Fills `array.data` from raw element bytes stored with `byte_order` ('<', '>', '|' or '=') in
// C or Fortran order, converting to C order and native byte order. Throws InputError (naming
// `where`) when `raw` does not hold exactly count() * item_size bytes.
void set_array_data(NdArray& array, std::string_view raw, char byte_order, bool fortran_order,
                    const std::string& where);

}  // namespace mocap::io
