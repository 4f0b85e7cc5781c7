#pragma once
// Helpers shared by the graph tests: a temporary directory that cleans up after itself, file
// reading and writing, and a free TCP port on the loopback interface.

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/files.hpp"

namespace mocap::graph::testing {

using mocap::test::read_file;
using mocap::test::read_lines;
using mocap::test::TempDir;
using mocap::test::write_file;

// Asks the kernel for a free loopback port. Another process could take it before we bind it,
// which is unlikely enough for tests.
inline int free_tcp_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  socklen_t size = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  close(fd);
  return ntohs(address.sin_port);
}

// Fields of a test.collect line: stream seq frame type digest [capture_ns latency_us].
inline std::vector<std::string> fields(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> result;
  for (std::string f; in >> f;) result.push_back(f);
  return result;
}

}  // namespace mocap::graph::testing
