#pragma once
// Where the tests find ../shared/data (they run from the repository root), and a skip with a
// clear message when it is absent.

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "support/files.hpp"

namespace mocap::test {

inline std::filesystem::path shared_data() {
  return std::filesystem::path("..") / "shared" / "data";
}

// Use as: MOCAP_REQUIRE_SHARED("mocap/cmu31/01_01.bvh");
#define MOCAP_REQUIRE_SHARED(relative)                                         \
  do {                                                                         \
    if (!std::filesystem::exists(::mocap::test::shared_data() / (relative))) { \
      GTEST_SKIP() << "shared data absent: "                                   \
                   << (::mocap::test::shared_data() / (relative)).string()     \
                   << " (tests read ../shared/data beside the repository)";    \
    }                                                                          \
  } while (0)

}  // namespace mocap::test
