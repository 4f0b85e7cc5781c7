#pragma once
// A network namespace of this process's own with loopback up and the addresses 127.0.0.1..N, for
// several Aravis fake GigE cameras at once: each needs its own address (its control port, UDP
// 3956, is fixed), and inside the namespace nothing collides with other test runs on the host
// (no lock needed). Children (the fake cameras) inherit the namespace. Linux only; without the
// right to create namespaces (no root, user namespaces disabled) it says why and changes nothing.

#include <arpa/inet.h>
#include <fcntl.h>
#include <net/if.h>
#include <netinet/in.h>
#include <sched.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>

namespace mocap::test {

namespace detail {

inline bool write_file(const char* path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  return static_cast<bool>(out.flush());
}

inline std::string interface_call(int fd, unsigned long request, ifreq& ifr, const char* what) {
  if (ioctl(fd, request, &ifr) == 0) return {};
  return std::string(what) + " on " + ifr.ifr_name + ": " + std::strerror(errno);
}

inline void set_address(ifreq& ifr, const std::string& dotted) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  inet_pton(AF_INET, dotted.c_str(), &address.sin_addr);
  std::memcpy(&ifr.ifr_addr, &address, sizeof address);
}

}  // namespace detail

// Call while the process has a single thread (user namespaces require it): first in main().
// Returns an empty string on success, else why not.
inline std::string enter_private_loopback(int addresses) {
  if (unshare(CLONE_NEWNET) != 0) {
    // Not privileged: a user namespace of our own makes us root inside it.
    const uid_t uid = getuid();
    const gid_t gid = getgid();
    if (unshare(CLONE_NEWUSER | CLONE_NEWNET) != 0)
      return std::string("cannot create a network namespace: ") + std::strerror(errno);
    if (!detail::write_file("/proc/self/setgroups", "deny") ||
        !detail::write_file("/proc/self/uid_map", "0 " + std::to_string(uid) + " 1") ||
        !detail::write_file("/proc/self/gid_map", "0 " + std::to_string(gid) + " 1"))
      return "cannot map this user into its user namespace";
  }
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return std::string("socket: ") + std::strerror(errno);
  std::string error;
  for (int i = 1; i <= addresses && error.empty(); ++i) {
    // 127.0.0.1 on lo itself, the others as aliases lo:2, lo:3, ... (listed by getifaddrs,
    // where Aravis looks an interface's address up).
    ifreq ifr{};
    const std::string name = i == 1 ? "lo" : "lo:" + std::to_string(i);
    std::memcpy(ifr.ifr_name, name.c_str(), std::min<std::size_t>(name.size(), IFNAMSIZ - 1));
    detail::set_address(ifr, "127.0.0." + std::to_string(i));
    error = detail::interface_call(fd, SIOCSIFADDR, ifr, "SIOCSIFADDR");
    if (!error.empty()) break;
    detail::set_address(ifr, "255.0.0.0");
    error = detail::interface_call(fd, SIOCSIFNETMASK, ifr, "SIOCSIFNETMASK");
    if (!error.empty()) break;
    error = detail::interface_call(fd, SIOCGIFFLAGS, ifr, "SIOCGIFFLAGS");
    if (!error.empty()) break;
    ifr.ifr_flags = static_cast<short>(ifr.ifr_flags | IFF_UP | IFF_RUNNING);
    error = detail::interface_call(fd, SIOCSIFFLAGS, ifr, "SIOCSIFFLAGS");
  }
  close(fd);
  return error;
}

}  // namespace mocap::test
