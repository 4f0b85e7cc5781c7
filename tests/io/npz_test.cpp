#include "io/npz.hpp"

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "npy_fixtures.hpp"
#include "support/shared_data.hpp"

namespace mocap::io {
namespace {

using test::npy_bytes;
using test::PickleWriter;
using test::raw_bytes;
using test::zip_bytes;
using test::ZipEntry;

std::string npy_error(const std::string& bytes) {
  try {
    parse_npy(bytes, "t.npy");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Npy, NumericArrays) {
  const NpyContent f4 = parse_npy(
      npy_bytes("<f4", "(2, 3)", false, raw_bytes(std::vector<float>{1, 2, 3, 4, 5, 6})), "f4");
  EXPECT_EQ(f4.array.dtype, DType::float32);
  EXPECT_EQ(f4.array.shape, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(f4.array.to_floats(), (std::vector<float>{1, 2, 3, 4, 5, 6}));
  EXPECT_FALSE(f4.objects.has_value());

  // Fortran order (columns first) comes back in C order; version 2.0 header.
  const NpyContent fortran = parse_npy(
      npy_bytes("<i4", "(2, 3)", true, raw_bytes(std::vector<std::int32_t>{1, 4, 2, 5, 3, 6}), 2),
      "fortran");
  EXPECT_EQ(fortran.array.to_doubles(), (std::vector<double>{1, 2, 3, 4, 5, 6}));

  // Big-endian doubles, bytes, bools, a scalar and an empty array.
  const NpyContent big = parse_npy(
      npy_bytes(">f8", "(1,)", false, std::string("\x40\x09\x21\xfb\x54\x44\x2d\x18", 8)), "be");
  EXPECT_DOUBLE_EQ(big.array.to_doubles()[0], 3.141592653589793);
  EXPECT_EQ(parse_npy(npy_bytes("|u1", "(3,)", false, "\x01\x02\xff"), "u1").array.to_doubles(),
            (std::vector<double>{1, 2, 255}));
  EXPECT_EQ(parse_npy(npy_bytes("|b1", "(2,)", false, std::string("\x00\x01", 2)), "b1")
                .array.to_floats(),
            (std::vector<float>{0, 1}));
  const NpyContent scalar =
      parse_npy(npy_bytes("<i8", "()", false, raw_bytes(std::vector<std::int64_t>{-7})), "s");
  EXPECT_TRUE(scalar.array.shape.empty());
  EXPECT_EQ(scalar.array.to_doubles(), (std::vector<double>{-7}));
  EXPECT_EQ(parse_npy(npy_bytes("<f4", "(0, 15, 3)", false, ""), "empty").array.count(), 0u);
}

TEST(Npy, ObjectArrayCarriesAPickle) {
  PickleWriter w;
  w.proto(3).ndarray({}, "O8", "|", false, [](PickleWriter& p) {
    p.op(']').mark().op('}').mark().str("n").integer(15).op('u').op('e');
  });
  const NpyContent c = parse_npy(npy_bytes("|O", "()", false, w.stop().bytes()), "obj");
  EXPECT_EQ(c.array.dtype, DType::object);
  ASSERT_TRUE(c.objects.has_value());
  EXPECT_EQ(c.objects->root().item().at("n").as_int(), 15);
  EXPECT_THROW(c.array.to_doubles(), std::invalid_argument);
  // The header and the pickled array must agree on the shape.
  EXPECT_NE(npy_error(npy_bytes("|O", "(2,)", false, w.bytes())).find("does not match"),
            std::string::npos);
}

TEST(Npy, MalformedFilesAreInputErrors) {
  const std::string payload = raw_bytes(std::vector<float>{1, 2, 3});
  EXPECT_NE(npy_error("PK\x03\x04 is a ZIP, not .npy").find("magic"), std::string::npos);
  EXPECT_NE(npy_error("\x93NUMPY\x07").find("needs 1 bytes"), std::string::npos);
  EXPECT_NE(npy_error(npy_bytes("<f4", "(4,)", false, payload)).find("needs 16 bytes"),
            std::string::npos);
  EXPECT_NE(npy_error(npy_bytes("<f4", "(2,)", false, payload)).find("has 12"), std::string::npos);
  EXPECT_NE(npy_error(npy_bytes("<U3", "(1,)", false, "abc")).find("dtype '<U3'"),
            std::string::npos);
  EXPECT_NE(npy_error(npy_bytes("<f4", "(99999999999, 99999999999)", false, "")).find("overflows"),
            std::string::npos);
  std::string broken = npy_bytes("<f4", "(3,)", false, payload);
  broken.replace(broken.find("'shape'"), 7, "'shope'");
  EXPECT_NE(npy_error(broken).find("no valid 'shape'"), std::string::npos);
  std::string version9 = npy_bytes("<f4", "(3,)", false, payload);
  version9[6] = 9;
  EXPECT_NE(npy_error(version9).find("version 9"), std::string::npos);
}

TEST(Npy, CorruptedHeadersNeverCrash) {
  const std::string good = npy_bytes("<f4", "(3,)", false, raw_bytes(std::vector<float>{1, 2, 3}));
  std::mt19937 rng(23);
  for (int trial = 0; trial < 5000; ++trial) {
    std::string bytes = good;
    bytes[std::uniform_int_distribution<std::size_t>(0, 80)(rng)] = static_cast<char>(rng());
    try {
      parse_npy(bytes, "fuzz");
    } catch (const InputError&) {
    }
  }
}

std::string npz_error(const std::string& bytes, const std::string& key = "a",
                      const NpyLimits& limits = {}) {
  try {
    NpzFile::from_bytes(bytes, "t.npz", limits).read(key);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::vector<ZipEntry> two_arrays(bool deflate) {
  return {{"a.npy", npy_bytes("<f4", "(2,)", false, raw_bytes(std::vector<float>{1.5f, -2.0f})),
           deflate},
          {"b.npy", npy_bytes("<i8", "(3,)", false, raw_bytes(std::vector<std::int64_t>{7, 8, 9})),
           deflate}};
}

TEST(Npz, StoredAndDeflatedMembers) {
  for (bool deflate : {false, true}) {
    const NpzFile npz = NpzFile::from_bytes(zip_bytes(two_arrays(deflate), "a comment"), "t.npz");
    EXPECT_EQ(npz.keys(), (std::vector<std::string>{"a", "b"}));
    EXPECT_TRUE(npz.contains("b"));
    EXPECT_FALSE(npz.contains("c"));
    EXPECT_EQ(npz.read("a").array.to_floats(), (std::vector<float>{1.5f, -2.0f}));
    EXPECT_EQ(npz.read("b").array.to_doubles(), (std::vector<double>{7, 8, 9}));
    try {
      npz.read("c");
      FAIL();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("no array 'c' (has: a, b)"), std::string::npos);
    }
  }
}

TEST(Npz, Zip64SizesInTheCentralDirectory) {
  auto entries = two_arrays(true);
  entries[1].zip64_sizes = true;
  EXPECT_EQ(NpzFile::from_bytes(zip_bytes(entries), "z64").read("b").array.to_doubles()[2], 9.0);
}

TEST(Npz, DamagedArchivesAreInputErrors) {
  const std::string good = zip_bytes(two_arrays(true));
  EXPECT_NE(npz_error("").find("not a ZIP archive"), std::string::npos);
  EXPECT_NE(npz_error(std::string(100, 'x')).find("no end of central directory"),
            std::string::npos);
  // Every truncation: the end record is gone or the offsets point past the end.
  for (std::size_t n = 0; n < good.size(); ++n) {
    EXPECT_THROW(NpzFile::from_bytes(good.substr(0, n), "cut").read("b"), InputError) << n;
  }
  // A flipped byte inside the compressed data: inflate error or CRC mismatch.
  std::string flipped = good;
  flipped[40] = static_cast<char>(flipped[40] ^ 0x20);
  EXPECT_THROW(NpzFile::from_bytes(flipped, "flip").read("a"), InputError);
  // The directory claims more members than it can hold.
  std::string many = good;
  many[many.size() - 12] = static_cast<char>(0xff);
  many[many.size() - 11] = static_cast<char>(0x7f);
  EXPECT_NE(npz_error(many).find("claims"), std::string::npos);
  // Members larger than the limit are refused before inflating.
  NpyLimits small;
  small.zip.max_member_bytes = 64;
  EXPECT_NE(npz_error(good, "a", small).find("limit"), std::string::npos);
  // Unsupported compression method (bzip2 = 12) in the central directory.
  std::string bzip = good;
  const std::size_t directory = bzip.find("PK\x01\x02");
  bzip[directory + 10] = 12;
  EXPECT_NE(npz_error(bzip).find("compression method 12"), std::string::npos);
}

TEST(Npz, RandomCorruptionNeverCrashes) {
  const std::string good = zip_bytes(two_arrays(true));
  std::mt19937 rng(29);
  for (int trial = 0; trial < 5000; ++trial) {
    std::string bytes = good;
    for (int k = 0; k < 1 + trial % 3; ++k) {
      bytes[std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(rng)] =
          static_cast<char>(rng());
    }
    try {
      const NpzFile npz = NpzFile::from_bytes(bytes, "fuzz");
      for (const auto& key : npz.keys()) npz.read(key);
    } catch (const InputError&) {
    }
  }
}

// The shared VideoPose3D files: object arrays in deflated members.
TEST(NpzShared, HumanEvaArchivesOpen) {
  MOCAP_REQUIRE_SHARED("eval/humaneva_i_videopose3d/data_2d_humaneva15_gt.npz");
  const auto folder = ::mocap::test::shared_data() / "eval/humaneva_i_videopose3d";
  const NpzFile two_d = NpzFile::open(folder / "data_2d_humaneva15_gt.npz");
  EXPECT_EQ(two_d.keys(), (std::vector<std::string>{"positions_2d", "metadata"}));
  const NpyContent meta = two_d.read("metadata");
  const Pickle::Value m = meta.objects->root().item();
  EXPECT_EQ(m.at("layout_name").as_string(), "humaneva15");
  EXPECT_EQ(m.at("num_joints").as_int(), 15);
  EXPECT_EQ(m.at("keypoints_symmetry")[1][3].as_int(), 11);
  const NpzFile three_d = NpzFile::open(folder / "data_3d_humaneva15.npz");
  EXPECT_EQ(three_d.keys(), (std::vector<std::string>{"positions_3d"}));
}

// Flipped bytes in the real 3D archive's deflate stream, and cuts of its pickle.
TEST(NpzShared, CorruptedCopiesOfTheRealFileFailCleanly) {
  MOCAP_REQUIRE_SHARED("eval/humaneva_i_videopose3d/data_3d_humaneva15.npz");
  const auto path =
      ::mocap::test::shared_data() / "eval/humaneva_i_videopose3d/data_3d_humaneva15.npz";
  std::ifstream in(path, std::ios::binary);
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::mt19937 rng(31);
  for (int trial = 0; trial < 20; ++trial) {
    std::string bytes = good;
    bytes[std::uniform_int_distribution<std::size_t>(100, bytes.size() - 200)(rng)] ^= 0x11;
    EXPECT_THROW(NpzFile::from_bytes(bytes, "flip").read("positions_3d"), InputError);
  }
  const ZipArchive zip = ZipArchive::from_bytes(good, "real");
  const std::string npy = zip.extract(zip.members()[0]);
  for (int trial = 0; trial < 40; ++trial) {
    const std::size_t n = std::uniform_int_distribution<std::size_t>(0, npy.size() - 1)(rng);
    EXPECT_THROW(parse_npy(npy.substr(0, n), "cut"), InputError) << n;
  }
}

// Cross-check against NumPy itself when a Python with NumPy is installed (Debian python3-numpy):
// it writes arrays in every supported form, and the reader must return the same numbers.
TEST(NpzNumpy, MatchesWhatNumpyWrites) {
  const char* python = nullptr;
  for (const char* candidate : {"/usr/bin/python3", "python3"}) {
    const std::string probe = std::string(candidate) + " -c 'import numpy' >/dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) {
      python = candidate;
      break;
    }
  }
  if (python == nullptr) GTEST_SKIP() << "no python3 with numpy (apt-get install python3-numpy)";
  ::mocap::test::TempDir dir;
  const std::string script = R"PY(
import numpy as np, pickle, sys
d = sys.argv[1]
a = np.arange(24, dtype='<f4').reshape(2, 3, 4) / 7
np.savez(d + '/plain.npz', f4=a, be=a.astype('>f8'), fortran=np.asfortranarray(a.astype('<i2')),
         u1=np.array([0, 255], dtype='u1'), b1=np.array([True, False]), empty=np.zeros((0, 15, 3), 'f4'))
np.savez_compressed(d + '/compressed.npz', f4=a)
obj = {'Train/S1': {'Walking 1 chunk0': a, 'Jog 1 chunk2': a[:1]}, 'n': 15, 'x': 0.25, 'l': [1, 2],
       's': np.float32(1.5), 'b': b'\x00\xff'}
np.savez_compressed(d + '/object.npz', positions=obj)
array = np.array(obj, dtype=object)
for protocol in (2, 4, 5):
    with open(d + '/object_p%d.npy' % protocol, 'wb') as f:
        np.lib.format.write_array_header_1_0(f, np.lib.format.header_data_from_array_1_0(array))
        pickle.dump(array, f, protocol=protocol)
)PY";
  std::ofstream(dir.file("make.py")) << script;
  const std::string command =
      std::string(python) + " " + dir.file("make.py") + " " + dir.path().string();
  ASSERT_EQ(std::system(command.c_str()), 0);

  std::vector<double> expected(24);
  for (int i = 0; i < 24; ++i) expected[i] = static_cast<double>(static_cast<float>(i) / 7.0f);
  const NpzFile plain = NpzFile::open(dir.file("plain.npz"));
  const std::vector<double> f4 = plain.read("f4").array.to_doubles();
  for (int i = 0; i < 24; ++i)
    EXPECT_FLOAT_EQ(static_cast<float>(f4[i]), static_cast<float>(expected[i]));
  EXPECT_EQ(plain.read("be").array.to_doubles(), f4);
  EXPECT_EQ(plain.read("fortran").array.shape, (std::vector<std::size_t>{2, 3, 4}));
  const std::vector<double> ints = plain.read("fortran").array.to_doubles();
  for (int i = 0; i < 24; ++i) EXPECT_EQ(ints[i], std::floor(i / 7.0)) << i;
  EXPECT_EQ(plain.read("u1").array.to_doubles(), (std::vector<double>{0, 255}));
  EXPECT_EQ(plain.read("b1").array.to_doubles(), (std::vector<double>{1, 0}));
  EXPECT_EQ(plain.read("empty").array.count(), 0u);
  EXPECT_EQ(NpzFile::open(dir.file("compressed.npz")).read("f4").array.to_doubles(), f4);

  const auto check_object = [&](const NpyContent& c) {
    ASSERT_TRUE(c.objects.has_value());
    const Pickle::Value root = c.objects->root().item();
    EXPECT_EQ(root.at("Train/S1").at("Walking 1 chunk0").array().to_doubles(), f4);
    EXPECT_EQ(root.at("Train/S1").at("Jog 1 chunk2").array().shape,
              (std::vector<std::size_t>{1, 3, 4}));
    EXPECT_EQ(root.at("n").as_int(), 15);
    EXPECT_DOUBLE_EQ(root.at("x").as_real(), 0.25);
    EXPECT_EQ(root.at("l")[1].as_int(), 2);
    EXPECT_DOUBLE_EQ(root.at("s").as_real(), 1.5);
    EXPECT_EQ(root.at("b").as_string(), std::string("\x00\xff", 2));
  };
  check_object(NpzFile::open(dir.file("object.npz")).read("positions"));
  for (int protocol : {2, 4, 5}) {
    SCOPED_TRACE(protocol);
    check_object(read_npy(dir.file("object_p" + std::to_string(protocol) + ".npy")));
  }
}

}  // namespace
}  // namespace mocap::io
