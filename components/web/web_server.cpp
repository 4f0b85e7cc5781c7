// The one translation unit that includes Boost.Beast / Boost.Asio (their headers cost ~30 s of
// compile time; web_server.hpp keeps them away from everything else).

#include "web/web_server.hpp"

// Boost 1.74's asio/awaitable.hpp uses std::exchange without including <utility> (C++20, GCC 12).
#include <utility>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <atomic>
#include <cstdlib>
#include <deque>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

#include "web/page_assets.hpp"

namespace mocap::web {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Text = std::shared_ptr<const std::string>;

// Boost 1.74's Beast takes boost::string_view, not std::string_view.
beast::string_view bsv(std::string_view s) { return {s.data(), s.size()}; }

// More broadcasts than this waiting for the server thread are dropped (counted): the thread is
// stalled and handing it more would only grow memory.
constexpr int kMaxPendingBroadcasts = 256;

class WsSession;

// State shared by the sessions; touched only on the server thread, except the atomic counters.
struct Shared {
  ServerOptions options;
  std::set<std::shared_ptr<WsSession>> sessions;
  Text greeting, last;
  std::atomic<std::uint64_t> clients{0}, clients_total{0}, broadcasts{0}, sent{0}, dropped{0},
      http_requests{0};
  std::atomic<int> pending{0};
};

std::string_view content_type_of(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".wasm") return "application/wasm";
  return "application/octet-stream";
}

// /three/<rest> -> a file of the three package: only under build/ and examples/jsm/, no "..".
std::optional<std::filesystem::path> three_file(const std::filesystem::path& dir,
                                                std::string_view target) {
  constexpr std::string_view prefix = "/three/";
  if (dir.empty() || target.substr(0, prefix.size()) != prefix) return std::nullopt;
  const std::string_view rest = target.substr(prefix.size());
  if (rest.find("..") != std::string_view::npos || rest.find('\\') != std::string_view::npos ||
      rest.find('\0') != std::string_view::npos)
    return std::nullopt;
  if (rest.substr(0, 6) != "build/" && rest.substr(0, 13) != "examples/jsm/") return std::nullopt;
  return dir / std::filesystem::path(rest);
}

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket socket, Shared& shared) : ws_(std::move(socket)), shared_(shared) {}

  void run(http::request<http::string_body> request) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(64 * 1024);
    ws_.auto_fragment(false);  // one frame per message: the browser gets it in one piece
    ws_.async_accept(request,
                     [self = shared_from_this()](beast::error_code ec) { self->on_accept(ec); });
  }

  // Queues a frame; a full queue loses its oldest waiting frame (the one in flight stays).
  void send(Text text) {
    if (closed_) return;
    if (waiting_.size() >= std::max<std::size_t>(1, shared_.options.queue_frames)) {
      waiting_.pop_front();
      ++shared_.dropped;
    }
    waiting_.push_back(std::move(text));
    if (!in_flight_) write_next();
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    --shared_.clients;
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().close(ignored);
    shared_.sessions.erase(shared_from_this());
  }

 private:
  void on_accept(beast::error_code ec) {
    if (ec) {  // not a valid handshake (Beast has answered 400): end the connection now
      beast::error_code ignored;
      beast::get_lowest_layer(ws_).socket().close(ignored);
      return;
    }
    ++shared_.clients;
    ++shared_.clients_total;
    shared_.sessions.insert(shared_from_this());
    if (shared_.greeting) send(shared_.greeting);
    if (shared_.last) send(shared_.last);
    read_next();
  }
  void read_next() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->on_read(ec);
    });
  }
  void on_read(beast::error_code ec) {
    if (ec) return close();
    if (ws_.got_text() && shared_.options.on_message)
      shared_.options.on_message(beast::buffers_to_string(buffer_.data()));
    buffer_.consume(buffer_.size());
    read_next();
  }
  void write_next() {
    if (waiting_.empty() || closed_) return;
    in_flight_ = std::move(waiting_.front());
    waiting_.pop_front();
    ws_.text(true);
    ws_.async_write(
        asio::buffer(*in_flight_),
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_write(ec); });
  }
  void on_write(beast::error_code ec) {
    in_flight_.reset();
    if (ec) return close();
    ++shared_.sent;
    write_next();
  }

  websocket::stream<beast::tcp_stream> ws_;
  Shared& shared_;
  beast::flat_buffer buffer_;
  std::deque<Text> waiting_;
  Text in_flight_;
  bool closed_ = false;
};

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, Shared& shared) : stream_(std::move(socket)), shared_(shared) {}
  void run() { read_next(); }

 private:
  void read_next() {
    parser_.emplace();
    parser_->body_limit(64 * 1024);
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(
        stream_, buffer_, *parser_,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

  void on_read(beast::error_code ec) {
    if (ec) return shut_down();
    http::request<http::string_body> request = parser_->release();
    ++shared_.http_requests;
    if (websocket::is_upgrade(request)) {
      if (request.target() != "/ws") return shut_down();
      stream_.expires_never();
      std::make_shared<WsSession>(stream_.release_socket(), shared_)->run(std::move(request));
      return;
    }
    respond(request);
  }

  template <class Body>
  void write(std::shared_ptr<http::response<Body>> response) {
    response->prepare_payload();
    http::async_write(stream_, *response,
                      [self = shared_from_this(), response](beast::error_code ec, std::size_t) {
                        if (ec || response->need_eof()) return self->shut_down();
                        self->read_next();
                      });
  }

  void respond_text(const http::request<http::string_body>& request, http::status status,
                    std::string_view type, std::string body) {
    auto response = std::make_shared<http::response<http::string_body>>(status, request.version());
    response->set(http::field::content_type, bsv(type));
    response->set(http::field::cache_control, "no-store");
    response->keep_alive(request.keep_alive());
    if (request.method() != http::verb::head) response->body() = std::move(body);
    write(response);
  }

  void respond(const http::request<http::string_body>& request) {
    if (request.method() != http::verb::get && request.method() != http::verb::head)
      return respond_text(request, http::status::method_not_allowed, "text/plain", "GET only\n");
    std::string_view target(request.target().data(), request.target().size());
    target = target.substr(0, target.find('?'));
    if (target == "/") target = "/index.html";
    for (const PageFile& file : page_files()) {
      if (file.path == target)
        return respond_text(request, http::status::ok, file.content_type,
                            std::string(file.content));
    }
    if (const auto path = three_file(shared_.options.three_dir, target)) {
      http::file_body::value_type body;
      beast::error_code ec;
      body.open(path->c_str(), beast::file_mode::scan, ec);
      if (!ec) {
        auto response = std::make_shared<http::response<http::file_body>>(
            std::piecewise_construct, std::make_tuple(std::move(body)),
            std::make_tuple(http::status::ok, request.version()));
        response->set(http::field::content_type, bsv(content_type_of(*path)));
        response->keep_alive(request.keep_alive());
        return write(response);
      }
    }
    respond_text(request, http::status::not_found, "text/plain",
                 "not found: " + std::string(target) + "\n");
  }

  void shut_down() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
  }

  beast::tcp_stream stream_;
  Shared& shared_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

tcp::endpoint endpoint_of(asio::io_context& io, const std::string& host, int port) {
  beast::error_code ec;
  tcp::resolver resolver(io);
  const auto results = resolver.resolve(
      host, std::to_string(port), tcp::resolver::numeric_service | tcp::resolver::passive, ec);
  if (ec || results.empty())
    throw std::runtime_error("web server: cannot resolve host '" + host + "': " + ec.message());
  return results.begin()->endpoint();
}

}  // namespace

struct WebServer::Impl {
  asio::io_context io{1};
  Shared shared;
  tcp::acceptor acceptor{io};
  std::thread thread;
  std::string host;
  int port = 0;
  bool v6 = false;

  void accept_next() {
    acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
      if (ec == asio::error::operation_aborted) return;
      if (!ec) std::make_shared<HttpSession>(std::move(socket), shared)->run();
      accept_next();
    });
  }
};

WebServer::WebServer(ServerOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.host = options.host;
  if (!options.greeting.empty())
    s.shared.greeting = std::make_shared<const std::string>(options.greeting);
  s.shared.options = std::move(options);
  const std::string where = s.host + ":" + std::to_string(s.shared.options.port);
  // asio keeps the low 16 bits: 99999 would serve on 34463.
  if (s.shared.options.port < 0 || s.shared.options.port > 65535)
    throw std::runtime_error("web server: port " + std::to_string(s.shared.options.port) +
                             " is not a TCP port (1 to 65535, or 0 for a free one)");
  try {
    const tcp::endpoint endpoint = endpoint_of(s.io, s.host, s.shared.options.port);
    s.acceptor.open(endpoint.protocol());
    s.acceptor.set_option(asio::socket_base::reuse_address(true));
    s.acceptor.bind(endpoint);
    s.acceptor.listen(asio::socket_base::max_listen_connections);
    // Kept here: the acceptor belongs to the server thread once it runs.
    s.port = s.acceptor.local_endpoint().port();
    s.v6 = s.acceptor.local_endpoint().address().is_v6();
  } catch (const boost::system::system_error& e) {
    throw std::runtime_error("web server: cannot listen on " + where + ": " + e.code().message());
  }
  s.accept_next();
  s.thread = std::thread([&s] { s.io.run(); });
}

WebServer::~WebServer() {
  Impl& s = *impl_;
  asio::post(s.io, [&s] {
    beast::error_code ignored;
    s.acceptor.close(ignored);
    const auto sessions = s.shared.sessions;  // close() erases from the set
    for (const auto& session : sessions) session->close();
    s.io.stop();
  });
  s.thread.join();
}

int WebServer::port() const { return impl_->port; }

std::string WebServer::url() const {
  return "http://" + (impl_->v6 ? "[" + impl_->host + "]" : impl_->host) + ":" +
         std::to_string(port()) + "/";
}

void WebServer::broadcast(std::string text) {
  Shared& shared = impl_->shared;
  ++shared.broadcasts;
  if (shared.pending.fetch_add(1) >= kMaxPendingBroadcasts) {
    --shared.pending;
    ++shared.dropped;
    return;
  }
  Text message = std::make_shared<const std::string>(std::move(text));
  asio::post(impl_->io, [&shared, message = std::move(message)] {
    --shared.pending;
    shared.last = message;
    for (const auto& session : shared.sessions) session->send(message);
  });
}

ServerStats WebServer::stats() const {
  const Shared& s = impl_->shared;
  return {s.clients.load(), s.clients_total.load(), s.broadcasts.load(),
          s.sent.load(),    s.dropped.load(),       s.http_requests.load()};
}

std::filesystem::path default_three_dir() {
  std::filesystem::path npm;
  if (const char* dir = std::getenv("MOCAP_NPM_DIR"); dir && *dir) {
    npm = dir;
  } else if (const char* cache = std::getenv("XDG_CACHE_HOME"); cache && *cache) {
    npm = std::filesystem::path(cache) / "mocap" / "npm";
  } else if (const char* home = std::getenv("HOME"); home && *home) {
    npm = std::filesystem::path(home) / ".cache" / "mocap" / "npm";
  } else {
    return {};
  }
  return npm / "node_modules" / "three";
}

}  // namespace mocap::web
