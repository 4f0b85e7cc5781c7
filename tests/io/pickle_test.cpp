#include "io/pickle.hpp"

#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "npy_fixtures.hpp"

namespace mocap::io {
namespace {

using test::PickleWriter;
using test::raw_bytes;

// A string literal with its embedded zero bytes.
template <std::size_t N>
std::string lit(const char (&s)[N]) {
  return std::string(s, N - 1);
}

std::string error_of(const std::string& bytes, const PickleLimits& limits = {}) {
  try {
    Pickle::parse(bytes, "test.pkl", limits);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Pickle, PlainValues) {
  PickleWriter w;
  w.proto(3).op('}').put(0).mark();
  w.str("int").integer(-5).str("real").real(2.5).str("none").none().str("yes").boolean(true);
  w.str("list").op(']').put(1).mark().op('K').op(7).op('M').op(0x34).op(0x12).op('e');
  w.str("tuple").short_str("a").short_str("b").op(0x86);
  w.str("long").op(0x8a).op(2).op(0x00).op(0x80);  // LONG1 of 2 bytes: -32768
  w.op('u').stop();
  const Pickle p = Pickle::parse(w.bytes(), "plain");
  const Pickle::Value d = p.root();
  ASSERT_EQ(d.kind(), Pickle::Kind::dict);
  EXPECT_EQ(d.dict_size(), 7u);
  EXPECT_EQ(d.at("int").as_int(), -5);
  EXPECT_DOUBLE_EQ(d.at("real").as_real(), 2.5);
  EXPECT_EQ(d.at("none").kind(), Pickle::Kind::none);
  EXPECT_TRUE(d.at("yes").as_bool());
  ASSERT_EQ(d.at("list").size(), 2u);
  EXPECT_EQ(d.at("list")[0].as_int(), 7);
  EXPECT_EQ(d.at("list")[1].as_int(), 0x1234);
  EXPECT_EQ(d.at("tuple")[1].as_string(), "b");
  EXPECT_EQ(d.at("long").as_int(), -32768);
  EXPECT_EQ(d.key(0).as_string(), "int");  // insertion order
  EXPECT_FALSE(d.find("absent").has_value());
  // Asking for the wrong kind names the source.
  try {
    d.at("list").as_string();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("plain: expected a str, found list"), std::string::npos);
  }
  EXPECT_THROW(d.at("absent"), InputError);
  EXPECT_THROW(d.at("list")[2], InputError);
}

TEST(Pickle, NumpyArraysWithByteOrderAndFortranOrder) {
  PickleWriter w;
  w.proto(3).op(']').mark();
  // float32 (2, 3), C order.
  w.ndarray({2, 3}, "f4", "<", false, [](PickleWriter& p) {
    p.bin(raw_bytes(std::vector<float>{1, 2, 3, 4, 5, 6}));
  });
  // big-endian float64 (2,): 1.5 and -2.
  w.ndarray({2}, "f8", ">", false, [](PickleWriter& p) {
    p.bin(std::string("\x3f\xf8\0\0\0\0\0\0\xc0\0\0\0\0\0\0\0", 16));
  });
  // int16 (2, 3) stored in Fortran order: columns first.
  w.ndarray({2, 3}, "i2", "<", true, [](PickleWriter& p) {
    p.bin(raw_bytes(std::vector<std::int16_t>{1, 4, 2, 5, 3, 6}));
  });
  w.op('e').stop();
  const Pickle p = Pickle::parse(w.bytes(), "arrays");
  const NdArray& a = p.root()[0].array();
  EXPECT_EQ(a.dtype, DType::float32);
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(a.to_floats(), (std::vector<float>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(p.root()[1].array().to_doubles(), (std::vector<double>{1.5, -2.0}));
  EXPECT_EQ(p.root()[2].array().to_doubles(), (std::vector<double>{1, 2, 3, 4, 5, 6}));
}

// VideoPose3D's layout: a 0-d object array holding {subject: {action: float32 array}}.
TEST(Pickle, ObjectArrayOfNestedDicts) {
  PickleWriter w;
  w.proto(3).ndarray({}, "O8", "|", false, [](PickleWriter& p) {
    p.op(']').mark().op('}').mark().str("Train/S1").op('}').mark().str("Walking 1 chunk0");
    p.ndarray({1, 1, 3}, "f4", "<", false, [](PickleWriter& q) {
      q.bin(raw_bytes(std::vector<float>{0.5f, 1.5f, 2.5f}));
    });
    p.op('u').op('u').op('e');
  });
  const Pickle p = Pickle::parse(w.stop().bytes(), "object");
  const Pickle::Value root = p.root();
  EXPECT_EQ(root.array().dtype, DType::object);
  const Pickle::Value dict = root.item();
  EXPECT_EQ(dict.at("Train/S1").at("Walking 1 chunk0").array().to_floats()[2], 2.5f);
  EXPECT_THROW(dict.item(), InputError);
}

TEST(Pickle, Protocol2BytesAndProtocol4Opcodes) {
  PickleWriter w;
  // _codecs.encode('\u00ff\u0001', 'latin1') is how protocol 2 writes bytes.
  w.proto(2)
      .op(']')
      .mark()
      .global("_codecs", "encode")
      .str("\xc3\xbf\x01")
      .str("latin1")
      .op(0x86)
      .op('R');
  // Protocol 4: FRAME, SHORT_BINUNICODE, MEMOIZE, STACK_GLOBAL for a numpy scalar float64 2.0.
  w.op(0x95).raw(std::string(8, '\0'));
  w.short_str("numpy.core.multiarray").op(0x94).short_str("scalar").op(0x94).op(0x93);
  w.dtype("f8", "<").bin(raw_bytes(std::vector<double>{2.0})).op(0x86).op('R');
  w.short_str("again").op(0x94).op('h').op(2);  // memo 2 is the string "again"
  w.op('e').stop();
  const Pickle p = Pickle::parse(w.bytes(), "p4");
  EXPECT_EQ(p.root()[0].as_string(), std::string("\xff\x01"));
  EXPECT_EQ(p.root()[0].kind(), Pickle::Kind::bytes);
  EXPECT_DOUBLE_EQ(p.root()[1].as_real(), 2.0);
  EXPECT_EQ(p.root()[3].as_string(), "again");
}

TEST(Pickle, RepeatedDictKeysKeepTheLastValue) {
  PickleWriter w;
  w.proto(3)
      .op('}')
      .mark()
      .str("a")
      .integer(1)
      .str("b")
      .integer(2)
      .str("a")
      .integer(3)
      .op('u')
      .stop();
  const Pickle p = Pickle::parse(w.bytes(), "dup");
  EXPECT_EQ(p.root().dict_size(), 2u);
  EXPECT_EQ(p.root().key(0).as_string(), "a");
  EXPECT_EQ(p.root().at("a").as_int(), 3);
}

TEST(Pickle, SelfReferenceAndDeepNestingAreHarmless) {
  // l = []; l.append(l), then a list nested 100000 deep through the memo.
  PickleWriter w;
  w.proto(3).op(']').put(0).get(0).op('a').op('0');
  w.op(']').put(1).op('0');
  for (int i = 0; i < 100000; ++i) w.op(']').get(1).op('a').put(1).op('0');
  w.get(1).stop();
  const Pickle p = Pickle::parse(w.bytes(), "deep");
  EXPECT_EQ(p.root().kind(), Pickle::Kind::list);
  EXPECT_EQ(p.root()[0].kind(), Pickle::Kind::list);
}

TEST(Pickle, RefusesWhatItDoesNotKnow) {
  PickleWriter evil;
  evil.proto(2).global("os", "system").str("echo hi").op(0x85).op('R').stop();
  EXPECT_NE(error_of(evil.bytes()).find("refuses global os.system"), std::string::npos);
  EXPECT_NE(error_of(lit("\x80\x03X\x01\x00\x00\x00"
                         "a"))
                .find("without STOP"),
            std::string::npos);
  EXPECT_NE(error_of("\x80\x03h\x05.").find("memo entry 5"), std::string::npos);
  EXPECT_NE(error_of("\x80\x03"
                     "a.")
                .find("stack underflow"),
            std::string::npos);
  EXPECT_NE(error_of("\x80\x03K\x01K\x02.").find("malformed stack"), std::string::npos);
  EXPECT_NE(error_of("\x80\x03S'x'\n.").find("opcode 0x53"), std::string::npos);
  EXPECT_NE(error_of("\x80\x09N.").find("protocol 9"), std::string::npos);
  EXPECT_NE(error_of("\x80\x03]K\x01K\x02s.").find("SETITEM: expected dict, found list"),
            std::string::npos);
  // A length of 4 GiB is checked against the input, never allocated.
  EXPECT_NE(error_of(lit("\x80\x03"
                         "B\xff\xff\xff\xff"))
                .find("needs 4294967295 bytes"),
            std::string::npos);
  // Array data that does not match the shape.
  PickleWriter short_data;
  short_data.proto(3).ndarray({4}, "f4", "<", false,
                              [](PickleWriter& p) { p.bin(std::string(12, '\0')); });
  EXPECT_NE(error_of(short_data.stop().bytes()).find("needs 16 bytes"), std::string::npos);
  PickleWriter bad_dtype;
  bad_dtype.proto(3).dtype("U8", "<").stop();
  EXPECT_NE(error_of(bad_dtype.bytes()).find("dtype 'U8'"), std::string::npos);
}

TEST(Pickle, LimitsStopRunawayInput) {
  PickleWriter many;
  many.proto(3).op(']').mark();
  for (int i = 0; i < 1000; ++i) many.integer(i);
  many.op('e').stop();
  PickleLimits limits;
  limits.max_values = 500;
  EXPECT_NE(error_of(many.bytes(), limits).find("more than 500 values"), std::string::npos);
  limits = {};
  limits.max_stack = 100;
  EXPECT_NE(error_of(many.bytes(), limits).find("stack deeper than 100"), std::string::npos);
  EXPECT_EQ(error_of(many.bytes()), "");
}

// Random corruptions of a valid pickle and random bytes: a result or an InputError, nothing else.
TEST(Pickle, GarbageNeverCrashes) {
  PickleWriter w;
  w.proto(3).ndarray({}, "O8", "|", false, [](PickleWriter& p) {
    p.op(']').mark().op('}').put(9).mark().str("k").op(']').mark();
    p.ndarray({2, 2}, "f4", "<", false, [](PickleWriter& q) {
      q.bin(raw_bytes(std::vector<float>{1, 2, 3, 4}));
    });
    p.get(9).op('e').op('u').op('e');
  });
  const std::string good = w.stop().bytes();
  ASSERT_EQ(error_of(good), "");
  std::mt19937 rng(17);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int trial = 0; trial < 20000; ++trial) {
    std::string bytes = good;
    const int flips = 1 + trial % 4;
    for (int k = 0; k < flips; ++k) {
      bytes[std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(rng)] =
          static_cast<char>(byte(rng));
    }
    if (trial % 5 == 0)
      bytes.resize(std::uniform_int_distribution<std::size_t>(0, bytes.size())(rng));
    try {
      const Pickle p = Pickle::parse(bytes, "fuzz");
      (void)p.root().kind();
    } catch (const InputError&) {
    }
  }
  for (int trial = 0; trial < 2000; ++trial) {
    std::string bytes(static_cast<std::size_t>(byte(rng)), '\0');
    for (char& c : bytes) c = static_cast<char>(byte(rng));
    try {
      Pickle::parse("\x80\x03" + bytes, "random");
    } catch (const InputError&) {
    }
  }
}

}  // namespace
}  // namespace mocap::io
