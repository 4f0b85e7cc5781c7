#pragma once
// Writers of small .npy, pickle and ZIP byte strings for the reader tests: each test builds
// exactly the bytes it needs (valid, or broken in one known way) without Python.

#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <zlib.h>

namespace mocap::io::test {

inline void put_le(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xff));
}

template <typename T>
std::string raw_bytes(const std::vector<T>& values) {
  std::string out(values.size() * sizeof(T), '\0');
  if (!values.empty()) std::memcpy(out.data(), values.data(), out.size());
  return out;
}

// A .npy file (version 1.0) with the given header fields and payload.
inline std::string npy_bytes(const std::string& descr, const std::string& shape, bool fortran,
                             const std::string& payload, int version = 1) {
  std::string header = "{'descr': '" + descr +
                       "', 'fortran_order': " + (fortran ? "True" : "False") +
                       ", 'shape': " + shape + ", }";
  while ((header.size() + 11) % 64 != 63) header.push_back(' ');
  header.push_back('\n');
  std::string out = "\x93NUMPY";
  out.push_back(static_cast<char>(version));
  out.push_back(0);
  put_le(out, header.size(), version == 1 ? 2 : 4);
  return out + header + payload;
}

// Emits pickle opcodes (protocol 2-4 subset) one call at a time.
class PickleWriter {
 public:
  PickleWriter& proto(int p) { return op(0x80).byte(p); }
  PickleWriter& stop() { return op('.'); }
  PickleWriter& mark() { return op('('); }
  PickleWriter& none() { return op('N'); }
  PickleWriter& boolean(bool b) { return op(b ? 0x88 : 0x89); }
  PickleWriter& integer(std::int32_t v) {
    op('J');
    put_le(bytes_, static_cast<std::uint32_t>(v), 4);
    return *this;
  }
  PickleWriter& real(double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, 8);
    op('G');
    for (int i = 7; i >= 0; --i) bytes_.push_back(static_cast<char>((bits >> (8 * i)) & 0xff));
    return *this;
  }
  PickleWriter& str(const std::string& s) {
    op('X');
    put_le(bytes_, s.size(), 4);
    bytes_ += s;
    return *this;
  }
  PickleWriter& short_str(const std::string& s) {
    op(0x8c).byte(static_cast<int>(s.size()));
    bytes_ += s;
    return *this;
  }
  PickleWriter& bin(const std::string& b) {
    op('B');
    put_le(bytes_, b.size(), 4);
    bytes_ += b;
    return *this;
  }
  PickleWriter& global(const std::string& module, const std::string& name) {
    op('c');
    bytes_ += module + "\n" + name + "\n";
    return *this;
  }
  PickleWriter& put(int index) { return op('q').byte(index); }
  PickleWriter& get(int index) { return op('h').byte(index); }
  PickleWriter& op(int code) { return byte(code); }
  PickleWriter& raw(const std::string& b) {
    bytes_ += b;
    return *this;
  }

  // numpy.dtype(code, False, True) with its BUILD state naming the byte order.
  PickleWriter& dtype(const std::string& code, const std::string& order) {
    global("numpy", "dtype").str(code).boolean(false).boolean(true).op(0x87).op('R');
    mark().integer(3).str(order).none().none().none().integer(-1).integer(-1).integer(0).op('t');
    return op('b');
  }
  // An ndarray as NumPy pickles it: _reconstruct(ndarray, (0,), b'b') then BUILD with
  // (1, shape, dtype, fortran, data). `data` emits the bytes or the object list.
  template <typename Data>
  PickleWriter& ndarray(const std::vector<int>& shape, const std::string& code,
                        const std::string& order, bool fortran, Data data) {
    global("numpy.core.multiarray", "_reconstruct").global("numpy", "ndarray");
    integer(0).op(0x85).op('C').byte(1).raw("b").op(0x87).op('R');
    mark().integer(1).mark();
    for (int d : shape) integer(d);
    op('t');
    dtype(code, order).boolean(fortran);
    data(*this);
    return op('t').op('b');
  }

  const std::string& bytes() const { return bytes_; }

 private:
  PickleWriter& byte(int b) {
    bytes_.push_back(static_cast<char>(b));
    return *this;
  }
  std::string bytes_;
};

// A pickled float32 array of the given shape and values, as a whole pickle.
inline std::string pickled_float_array(const std::vector<int>& shape, const std::vector<float>& v) {
  PickleWriter w;
  w.proto(3).ndarray(shape, "f4", "<", false, [&](PickleWriter& p) { p.bin(raw_bytes(v)); });
  return w.stop().bytes();
}

// Raw deflate, as ZIP stores it.
inline std::string deflate_raw(const std::string& data) {
  z_stream z{};
  deflateInit2(&z, 6, Z_DEFLATED, -MAX_WBITS, 8, Z_DEFAULT_STRATEGY);
  std::string out(deflateBound(&z, data.size()) + 16, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = static_cast<uInt>(data.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

struct ZipEntry {
  std::string name;
  std::string data;
  bool deflate = true;
  bool zip64_sizes = false;  // central directory sizes as 0xffffffff + ZIP64 extra field
};

// A ZIP archive of the entries (no data descriptors), optionally followed by a comment.
inline std::string zip_bytes(const std::vector<ZipEntry>& entries,
                             const std::string& comment = "") {
  std::string out, directory;
  for (const auto& e : entries) {
    const std::string stored = e.deflate ? deflate_raw(e.data) : e.data;
    const auto crc = static_cast<std::uint32_t>(
        crc32(0, reinterpret_cast<const Bytef*>(e.data.data()), static_cast<uInt>(e.data.size())));
    const std::size_t offset = out.size();
    put_le(out, 0x04034b50, 4);
    put_le(out, 20, 2);
    put_le(out, 0, 2);
    put_le(out, e.deflate ? 8 : 0, 2);
    put_le(out, 0, 4);  // time, date
    put_le(out, crc, 4);
    put_le(out, stored.size(), 4);
    put_le(out, e.data.size(), 4);
    put_le(out, e.name.size(), 2);
    put_le(out, 0, 2);
    out += e.name + stored;

    std::string extra;
    if (e.zip64_sizes) {
      put_le(extra, 0x0001, 2);
      put_le(extra, 16, 2);
      put_le(extra, e.data.size(), 8);
      put_le(extra, stored.size(), 8);
    }
    put_le(directory, 0x02014b50, 4);
    put_le(directory, 20, 2);
    put_le(directory, 20, 2);
    put_le(directory, 0, 2);
    put_le(directory, e.deflate ? 8 : 0, 2);
    put_le(directory, 0, 4);
    put_le(directory, crc, 4);
    put_le(directory, e.zip64_sizes ? 0xffffffffu : stored.size(), 4);
    put_le(directory, e.zip64_sizes ? 0xffffffffu : e.data.size(), 4);
    put_le(directory, e.name.size(), 2);
    put_le(directory, extra.size(), 2);
    put_le(directory, 0, 2);  // comment
    put_le(directory, 0, 2);  // disk
    put_le(directory, 0, 2);  // internal attributes
    put_le(directory, 0, 4);  // external attributes
    put_le(directory, offset, 4);
    directory += e.name + extra;
  }
  const std::size_t directory_offset = out.size();
  out += directory;
  put_le(out, 0x06054b50, 4);
  put_le(out, 0, 2);
  put_le(out, 0, 2);
  put_le(out, entries.size(), 2);
  put_le(out, entries.size(), 2);
  put_le(out, directory.size(), 4);
  put_le(out, directory_offset, 4);
  put_le(out, comment.size(), 2);
  return out + comment;
}

}  // namespace mocap::io::test
