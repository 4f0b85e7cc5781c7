#pragma once
// Whether the network models fetched by tools/setup.sh are in the cache, and a skip with the
// command that fetches them when they are not.

#include <gtest/gtest.h>

#include "detect/model_files.hpp"

namespace mocap::test {

inline bool movenet_model_present() {
  try {
    detect::movenet_model_json();
    return true;
  } catch (const detect::ModelMissing&) {
    return false;
  }
}

// Use as the first statement of a test that runs MoveNet MultiPose.
#define MOCAP_REQUIRE_MOVENET()                                             \
  do {                                                                      \
    if (!::mocap::test::movenet_model_present())                            \
      GTEST_SKIP() << "MoveNet model absent: tools/setup.sh --models-only"; \
  } while (0)

}  // namespace mocap::test
