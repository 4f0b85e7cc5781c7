#pragma once
// Checks of what an interrupted `mocap reconstruct` leaves, shared by the tests that stop one.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/files.hpp"

namespace mocap::test {

// poses.jsonl's lines, each whole JSON (a cut line fails), their frames strictly increasing.
// `log`: the run's messages, shown with a failure.
inline std::vector<std::string> expect_whole_poses_in_order(const std::string& path,
                                                            const std::string& log) {
  const std::vector<std::string> lines = read_lines(path);
  std::int64_t last = -1;
  for (const std::string& line : lines) {
    if (!nlohmann::json::accept(line)) {
      ADD_FAILURE() << "a cut line in " << path << ": " << line << "\n" << log;
      continue;
    }
    const std::int64_t frame = nlohmann::json::parse(line).at("frame").get<std::int64_t>();
    EXPECT_GT(frame, last) << path << "\n" << log;
    last = frame;
  }
  return lines;
}

// summary.json parsed; a failure (and null) when it is not whole JSON.
inline nlohmann::json read_summary(const std::string& path, const std::string& log) {
  const std::string text = read_file(path);
  if (!nlohmann::json::accept(text)) {
    ADD_FAILURE() << path << " is not whole JSON: " << text << "\n" << log;
    return nullptr;
  }
  return nlohmann::json::parse(text);
}

}  // namespace mocap::test
