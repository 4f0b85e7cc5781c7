#pragma once
// A free TCP port on the loopback interface, for tests that bind real sockets.

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

namespace mocap::test {

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

}  // namespace mocap::test
