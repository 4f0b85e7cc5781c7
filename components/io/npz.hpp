#pragma once
// NumPy's .npy (one array) and .npz (a ZIP of .npy files, from np.savez / np.savez_compressed).
//
// A .npy file is the magic "\x93NUMPY", a version (1.0, 2.0 or 3.0), a header length (2 bytes in
// 1.0, 4 bytes after) and a Python dict literal such as
// {'descr': '<f4', 'fortran_order': False, 'shape': (613, 15, 3), }, then the raw elements.
// Object arrays ('descr': '|O') are followed by a pickle of the whole array instead; those are
// read with the restricted reader of pickle.hpp (VideoPose3D stores its datasets that way).

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/ndarray.hpp"
#include "io/pickle.hpp"
#include "io/zip_archive.hpp"

namespace mocap::io {

struct NpyLimits {
  ZipLimits zip;        // for .npz archives; zip.max_member_bytes also caps a .npy file
  PickleLimits pickle;  // for object arrays
};

struct NpyContent {
  NdArray array;                  // numeric arrays; object arrays: dtype object and shape only
  std::optional<Pickle> objects;  // object arrays: objects->root() is the array (see item())
};

// Parses the bytes of one .npy file; throws InputError naming `source`.
NpyContent parse_npy(std::string_view bytes, const std::string& source,
                     const NpyLimits& limits = {});
NpyContent read_npy(const std::filesystem::path& file, const NpyLimits& limits = {});

class NpzFile {
 public:
  static NpzFile open(const std::filesystem::path& file, const NpyLimits& limits = {});
  static NpzFile from_bytes(std::string bytes, std::string source, const NpyLimits& limits = {});

  // The array names: the member names without ".npy", in archive order.
  std::vector<std::string> keys() const;
  bool contains(std::string_view key) const;
  // Reads one array; throws InputError if there is no such key or it is malformed.
  NpyContent read(std::string_view key) const;

 private:
  NpzFile(ZipArchive zip, const NpyLimits& limits) : zip_(std::move(zip)), limits_(limits) {}
  ZipArchive zip_;
  NpyLimits limits_;
};

}  // namespace mocap::io
