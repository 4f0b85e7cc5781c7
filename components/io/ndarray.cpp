#include "io/ndarray.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "core/input_error.hpp"

namespace mocap::io {
namespace {

struct DTypeInfo {
  DType dtype;
  std::string_view code;
  std::size_t size;
  std::string_view name;
};

constexpr DTypeInfo kDTypes[] = {
    {DType::boolean, "b1", 1, "bool"},    {DType::int8, "i1", 1, "int8"},
    {DType::uint8, "u1", 1, "uint8"},     {DType::int16, "i2", 2, "int16"},
    {DType::uint16, "u2", 2, "uint16"},   {DType::int32, "i4", 4, "int32"},
    {DType::uint32, "u4", 4, "uint32"},   {DType::int64, "i8", 8, "int64"},
    {DType::uint64, "u8", 8, "uint64"},   {DType::float32, "f4", 4, "float32"},
    {DType::float64, "f8", 8, "float64"}, {DType::object, "O8", 8, "object"},
};

const DTypeInfo& info(DType dtype) { return kDTypes[static_cast<int>(dtype)]; }

template <typename T>
T load(const char* p) {
  T value;
  std::memcpy(&value, p, sizeof value);
  return value;
}

template <typename Out>
std::vector<Out> convert(const NdArray& a) {
  if (a.dtype == DType::object) {
    throw std::invalid_argument("an object array has no numeric elements");
  }
  const std::size_t n = a.count(), size = item_size(a.dtype);
  std::vector<Out> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char* p = a.data.data() + i * size;
    switch (a.dtype) {
      case DType::boolean:
        out[i] = static_cast<Out>(p[0] != 0);
        break;
      case DType::int8:
        out[i] = static_cast<Out>(load<std::int8_t>(p));
        break;
      case DType::uint8:
        out[i] = static_cast<Out>(load<std::uint8_t>(p));
        break;
      case DType::int16:
        out[i] = static_cast<Out>(load<std::int16_t>(p));
        break;
      case DType::uint16:
        out[i] = static_cast<Out>(load<std::uint16_t>(p));
        break;
      case DType::int32:
        out[i] = static_cast<Out>(load<std::int32_t>(p));
        break;
      case DType::uint32:
        out[i] = static_cast<Out>(load<std::uint32_t>(p));
        break;
      case DType::int64:
        out[i] = static_cast<Out>(load<std::int64_t>(p));
        break;
      case DType::uint64:
        out[i] = static_cast<Out>(load<std::uint64_t>(p));
        break;
      case DType::float32:
        out[i] = static_cast<Out>(load<float>(p));
        break;
      case DType::float64:
        out[i] = static_cast<Out>(load<double>(p));
        break;
      case DType::object:
        break;
    }
  }
  return out;
}

bool needs_swap(char byte_order) {
  constexpr bool little = std::endian::native == std::endian::little;
  return (byte_order == '<' && !little) || (byte_order == '>' && little);
}

void swap_elements(std::string& data, std::size_t size) {
  for (std::size_t i = 0; i + size <= data.size(); i += size) {
    std::reverse(data.begin() + static_cast<std::ptrdiff_t>(i),
                 data.begin() + static_cast<std::ptrdiff_t>(i + size));
  }
}

// Element i (C order) sits at the Fortran offset sum(index_k * stride_k), stride_0 = 1.
std::string fortran_to_c(const std::string& data, const std::vector<std::size_t>& shape,
                         std::size_t size) {
  const std::size_t dims = shape.size();
  std::vector<std::size_t> stride(dims, 1);
  for (std::size_t k = 1; k < dims; ++k) stride[k] = stride[k - 1] * shape[k - 1];
  std::string out(data.size(), '\0');
  const std::size_t n = data.size() / size;
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t rest = i, offset = 0;
    for (std::size_t k = dims; k-- > 0;) {
      offset += (rest % shape[k]) * stride[k];
      rest /= shape[k];
    }
    std::memcpy(out.data() + i * size, data.data() + offset * size, size);
  }
  return out;
}

}  // namespace

std::size_t item_size(DType dtype) { return info(dtype).size; }
std::string_view to_string(DType dtype) { return info(dtype).name; }

bool parse_dtype_code(std::string_view code, DType& out) {
  if (code == "O" || code == "O8") {
    out = DType::object;
    return true;
  }
  if (code == "?") code = "b1";  // NumPy's one-character code for bool
  for (const auto& d : kDTypes) {
    if (d.code == code) {
      out = d.dtype;
      return true;
    }
  }
  return false;
}

bool element_count(const std::vector<std::size_t>& shape, std::size_t& count) {
  constexpr std::size_t kMax = std::numeric_limits<std::size_t>::max() / 8;
  count = 1;
  for (std::size_t d : shape) {
    if (d != 0 && count > kMax / d) return false;
    count *= d;
  }
  return true;
}

std::size_t NdArray::count() const {
  std::size_t n = 0;
  return element_count(shape, n) ? n : 0;
}

std::vector<double> NdArray::to_doubles() const { return convert<double>(*this); }
std::vector<float> NdArray::to_floats() const { return convert<float>(*this); }

void set_array_data(NdArray& array, std::string_view raw, char byte_order, bool fortran_order,
                    const std::string& where) {
  std::size_t n = 0;
  if (!element_count(array.shape, n)) throw InputError(where, "array shape overflows");
  const std::size_t size = item_size(array.dtype);
  if (raw.size() / size != n || raw.size() % size != 0) {
    throw InputError(where, "array of " + std::to_string(n) + " " +
                                std::string(to_string(array.dtype)) + " elements needs " +
                                std::to_string(n * size) + " bytes, the data has " +
                                std::to_string(raw.size()));
  }
  array.data.assign(raw);
  if (needs_swap(byte_order) && size > 1) swap_elements(array.data, size);
  if (fortran_order && array.shape.size() > 1)
    array.data = fortran_to_c(array.data, array.shape, size);
}

}  // namespace mocap::io
