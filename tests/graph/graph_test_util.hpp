#pragma once
// Helpers shared by the graph tests: a temporary directory that cleans up after itself, file
// reading and writing, and a free TCP port on the loopback interface.

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/files.hpp"
#include "support/network.hpp"

namespace mocap::graph::testing {

using mocap::test::read_file;
using mocap::test::read_lines;
using mocap::test::TempDir;
using mocap::test::write_file;

using mocap::test::free_tcp_port;

// Fields of a test.collect line: stream seq frame type digest [capture_ns latency_us].
inline std::vector<std::string> fields(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> result;
  for (std::string f; in >> f;) result.push_back(f);
  return result;
}

}  // namespace mocap::graph::testing
