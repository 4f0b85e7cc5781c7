#include "io/trc.hpp"

#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/input_error.hpp"

namespace mocap::io {
namespace {

const std::string kTrc =
    "PathFileType\t4\t(X/Y/Z)\tdemo.trc\n"
    "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\n"
    "60.0\t60.0\t2\t2\tmm\t60.0\n"
    "Frame#\tTime\tA\t\t\tB\t\t\t\n"
    "\t\tX1\tY1\tZ1\tX2\tY2\tZ2\n"
    "\n"
    "1\t0.0166\t1000\t2000\t3000\t-1\t0\t1\n"
    "2\t0.0333\t1100\t2100\t3100\t\t\t\n";

std::string message_of(const std::string& text) {
  try {
    parse_trc(text, "demo.trc");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Trc, ReadsMarkersFramesAndUnits) {
  const TrcFile f = parse_trc(kTrc, "demo.trc");
  EXPECT_EQ(f.rate, 60.0);
  ASSERT_EQ(f.markers.size(), 2u);
  EXPECT_EQ(f.markers[1], "B");
  EXPECT_EQ(f.marker("B"), 1u);
  EXPECT_FALSE(f.marker("C").has_value());
  ASSERT_EQ(f.frames.size(), 2u);
  EXPECT_FLOAT_EQ(f.frames[0][0].x, 1.0f);  // millimetres to metres
  EXPECT_FLOAT_EQ(f.frames[0][0].z, 3.0f);
  EXPECT_FLOAT_EQ(f.frames[0][1].x, -0.001f);
  EXPECT_TRUE(std::isnan(f.frames[1][1].x));  // empty cells: missing
}

TEST(Trc, MalformedInputNamesFileAndLine) {
  EXPECT_NE(message_of("").find("demo.trc:1:"), std::string::npos);
  EXPECT_NE(message_of("hello\n").find("demo.trc:1: not a TRC file"), std::string::npos);
  const std::string truncated = kTrc.substr(0, kTrc.size() - 12);
  EXPECT_NE(message_of(truncated).find("demo.trc:8:"), std::string::npos) << message_of(truncated);
  std::string bad_number = kTrc;
  bad_number.replace(bad_number.find("2000"), 4, "2x00");
  EXPECT_NE(message_of(bad_number).find("demo.trc:7: marker 'A'"), std::string::npos)
      << message_of(bad_number);
  std::string short_file = kTrc.substr(0, kTrc.find("\n2\t"));
  EXPECT_NE(message_of(short_file).find("NumFrames says 2"), std::string::npos)
      << message_of(short_file);
  std::string units = kTrc;
  units.replace(units.find("\tmm\t"), 4, "\tft\t");
  EXPECT_NE(message_of(units).find("demo.trc:3: unknown Units"), std::string::npos);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 300; ++trial) {
    std::string noise = kTrc;
    for (int k = 0; k < 4; ++k) noise[rng() % noise.size()] = static_cast<char>(rng() % 256);
    try {
      parse_trc(noise, "demo.trc");
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("demo.trc"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mocap::io
