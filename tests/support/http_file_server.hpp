#pragma once
// One file served over HTTP/1.1 on loopback, for tests of network streams: it answers byte-range
// requests (206, so FFmpeg can seek), closes every connection after its response, and can stop
// sending after the first `cut` bytes of the file while announcing all of them: a stream that
// stops mid-file, as when the connection to a server is lost.

#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace mocap::test {

class HttpFileServer {
 public:
  explicit HttpFileServer(std::string bytes,
                          std::size_t cut = std::numeric_limits<std::size_t>::max())
      : bytes_(std::move(bytes)), cut_(std::min(cut, bytes_.size())) {
    listener_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (bind(listener_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        listen(listener_, 8) != 0)
      throw std::runtime_error("HttpFileServer: cannot listen on loopback");
    socklen_t size = sizeof address;
    getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &size);
    port_ = ntohs(address.sin_port);
    acceptor_ = std::thread([this] { accept_loop(); });
  }
  ~HttpFileServer() {
    stop_ = true;
    acceptor_.join();
    for (std::thread& t : connections_) t.join();
    close(listener_);
  }
  HttpFileServer(const HttpFileServer&) = delete;
  HttpFileServer& operator=(const HttpFileServer&) = delete;

  std::string url(const std::string& name) const {
    return "http://127.0.0.1:" + std::to_string(port_) + "/" + name;
  }

 private:
  void accept_loop() {
    while (!stop_) {
      pollfd p{listener_, POLLIN, 0};
      if (poll(&p, 1, 50) <= 0) continue;
      const int fd = accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
      if (fd >= 0) connections_.emplace_back([this, fd] { serve(fd); });
    }
  }

  void serve(int fd) {
    timeval timeout{5, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
    std::string request;
    char buffer[4096];
    while (request.find("\r\n\r\n") == std::string::npos && request.size() < 65536 && !stop_) {
      const ssize_t n = recv(fd, buffer, sizeof buffer, 0);
      if (n <= 0) break;
      request.append(buffer, static_cast<std::size_t>(n));
    }
    std::size_t start = 0;
    bool ranged = false;
    for (const char* key : {"Range: bytes=", "range: bytes="}) {
      if (const auto at = request.find(key); at != std::string::npos) {
        start = std::stoull(request.substr(at + std::char_traits<char>::length(key)));
        ranged = true;
      }
    }
    const std::size_t size = bytes_.size();
    std::string head;
    if (start >= size && ranged) {
      head = "HTTP/1.1 416 Range Not Satisfiable\r\nContent-Range: bytes */" +
             std::to_string(size) + "\r\nContent-Length: 0\r\nConnection: close\r\n\r\n";
    } else {
      head = std::string(ranged ? "HTTP/1.1 206 Partial Content\r\n" : "HTTP/1.1 200 OK\r\n") +
             "Content-Type: video/x-msvideo\r\nAccept-Ranges: bytes\r\nContent-Length: " +
             std::to_string(size - start) + "\r\n";
      if (ranged)
        head += "Content-Range: bytes " + std::to_string(start) + "-" + std::to_string(size - 1) +
                "/" + std::to_string(size) + "\r\n";
      head += "Connection: close\r\n\r\n";
    }
    send_all(fd, head);
    if (start < cut_) send_all(fd, std::string_view(bytes_).substr(start, cut_ - start));
    shutdown(fd, SHUT_RDWR);
    close(fd);
  }

  void send_all(int fd, std::string_view data) const {
    while (!data.empty() && !stop_) {
      const ssize_t n = send(fd, data.data(), data.size(), MSG_NOSIGNAL);
      if (n <= 0) return;
      data.remove_prefix(static_cast<std::size_t>(n));
    }
  }

  std::string bytes_;
  std::size_t cut_;
  int listener_ = -1;
  int port_ = 0;
  std::atomic<bool> stop_{false};
  std::thread acceptor_;
  std::vector<std::thread> connections_;  // touched by the acceptor thread only, joined after it
};

}  // namespace mocap::test
