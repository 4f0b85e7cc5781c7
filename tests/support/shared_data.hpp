#pragma once
// Where the tests find ../shared/data (they run from the repository root), and a skip with a
// clear message when it is absent.

#include <filesystem>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

namespace mocap::test {

inline std::filesystem::path shared_data() { return std::filesystem::path("..") / "shared" / "data"; }

// Use as: MOCAP_REQUIRE_SHARED("mocap/cmu31/01_01.bvh");
#define MOCAP_REQUIRE_SHARED(relative)                                                          \
  do {                                                                                          \
    if (!std::filesystem::exists(::mocap::test::shared_data() / (relative))) {                  \
      GTEST_SKIP() << "shared data absent: " << (::mocap::test::shared_data() / (relative)).string() \
                   << " (tests read ../shared/data beside the repository)";                    \
    }                                                                                           \
  } while (0)

// A fresh temporary folder removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() /
            ("mocap-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter()++));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  static int& counter() {
    static int n = 0;
    return n;
  }
  std::filesystem::path path_;
};

}  // namespace mocap::test
