#include "graph/keys.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <regex>
#include <sstream>

#include "core/input_error.hpp"
#include "graph/node.hpp"

namespace mocap::graph {
namespace fs = std::filesystem;

namespace {

constexpr std::size_t kMaxKeyFileBytes = 4096;

std::string mode_text(mode_t mode) {
  std::ostringstream out;
  out << std::oct << (mode & 07777);
  return "0" + out.str();
}

// The key of a key file: its only line that is neither blank nor a comment.
std::string key_of(const std::string& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) {
    throw InputError(path, std::string("cannot read the key file: ") + std::strerror(errno));
  }
  std::string text(kMaxKeyFileBytes + 1, '\0');
  std::size_t size = 0;
  while (size < text.size()) {
    const ssize_t n = read(fd, text.data() + size, text.size() - size);
    if (n <= 0) break;
    size += static_cast<std::size_t>(n);
  }
  close(fd);
  if (size > kMaxKeyFileBytes) throw InputError(path, "not a key file (larger than 4 KiB)");
  text.resize(size);
  std::istringstream lines(text);
  std::string key;
  for (std::string line; std::getline(lines, line);) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto last = line.find_last_not_of(" \t\r");
    if (!key.empty()) throw InputError(path, "not a key file (more than one key line)");
    key = line.substr(first, last - first + 1);
  }
  if (!looks_like_z85_key(key)) {
    throw InputError(path,
                     "not a key file (expected one line of 40 Z85 characters; make keys "
                     "with 'mocap keys generate')");
  }
  return key;
}

struct stat stat_of(const std::string& path) {
  struct stat info {};
  if (lstat(path.c_str(), &info) != 0) {
    throw InputError(path, errno == ENOENT
                               ? "no such key file (make one with 'mocap keys generate')"
                               : std::string("cannot read the key file: ") + std::strerror(errno));
  }
  if (!S_ISREG(info.st_mode)) throw InputError(path, "not a regular file");
  return info;
}

}  // namespace

fs::path default_key_dir() {
  if (const char* dir = std::getenv("MOCAP_KEY_DIR"); dir && *dir) return dir;
  if (const char* config = std::getenv("XDG_CONFIG_HOME"); config && *config) {
    return fs::path(config) / "mocap" / "keys";
  }
  const char* home = std::getenv("HOME");
  return fs::path(home && *home ? home : ".") / ".config" / "mocap" / "keys";
}

std::string resolve_key_reference(const std::string& reference, const fs::path& base) {
  if (reference.rfind("~/", 0) == 0) {
    const char* home = std::getenv("HOME");
    return (fs::path(home && *home ? home : ".") / reference.substr(2)).string();
  }
  const fs::path path(reference);
  if (path.is_absolute()) return path.string();
  if (reference.find('/') == std::string::npos) return (default_key_dir() / path).string();
  return (base / path).string();
}

std::string key_reference_problem(const std::string& reference) {
  if (reference.empty()) return "an empty key reference";
  if (looks_like_z85_key(reference)) {
    return "this looks like a key itself; a graph file names key files (e.g. keys/solve for "
           "keys/solve.key and keys/solve.pub), never keys";
  }
  static const std::regex pem(R"(-----BEGIN|PRIVATE KEY|[\n\r])");
  if (std::regex_search(reference, pem)) {
    return "this looks like key material; a graph file names key files, never keys";
  }
  return {};
}

std::string read_public_key_file(const std::string& path) {
  const struct stat info = stat_of(path);
  if (info.st_mode & (S_IWGRP | S_IWOTH)) {
    throw InputError(path, "others can write this public key file (mode " +
                               mode_text(info.st_mode) +
                               "), so they could put their own key in it; chmod go-w " + path);
  }
  return key_of(path);
}

std::string read_secret_key_file(const std::string& path) {
  const struct stat info = stat_of(path);
  if (info.st_mode & (S_IRWXG | S_IRWXO)) {
    throw InputError(path, "this secret key file is open to group or others (mode " +
                               mode_text(info.st_mode) + "); chmod 600 " + path);
  }
  if (geteuid() != 0 && info.st_uid != geteuid()) {
    throw InputError(path, "this secret key file belongs to another user (uid " +
                               std::to_string(info.st_uid) + ")");
  }
  const std::string key = key_of(path);
  try {
    curve_public_key(key);
  } catch (const std::exception& e) {
    throw InputError(path, e.what());
  }
  return key;
}

std::vector<std::string> read_public_keys(const std::string& resolved_reference) {
  std::error_code error;
  if (!fs::is_directory(resolved_reference, error)) {
    return {read_public_key_file(resolved_reference + ".pub")};
  }
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(resolved_reference, error)) {
    if (entry.path().extension() == ".pub") files.push_back(entry.path().string());
  }
  if (error) throw InputError(resolved_reference, "cannot list the folder: " + error.message());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(resolved_reference, "no *.pub key files in this folder");
  std::vector<std::string> keys;
  for (const std::string& file : files) keys.push_back(read_public_key_file(file));
  return keys;
}

CurveKeys load_curve_keys(const std::string& server, const std::vector<std::string>& clients,
                          bool binds) {
  CurveKeys keys;
  if (binds) {
    keys.secret_key = read_secret_key_file(server + ".key");
    for (const std::string& client : clients) {
      for (std::string& key : read_public_keys(client)) {
        keys.allowed_clients.push_back(std::move(key));
      }
    }
  } else {
    if (clients.size() != 1) {
      throw std::runtime_error("a connecting socket needs exactly one client key, not " +
                               std::to_string(clients.size()));
    }
    keys.server_public_key = read_public_key_file(server + ".pub");
    keys.secret_key = read_secret_key_file(clients.front() + ".key");
  }
  return keys;
}

CurveKeys node_curve_keys(const Context& ctx, bool binds) {
  const std::string server = ctx.param<std::string>("curve_server");
  if (server.empty()) return {};
  return load_curve_keys(server, ctx.param<std::vector<std::string>>("curve_client"), binds);
}

WrittenKeyPair write_key_pair(const std::string& name, const fs::path& dir, bool force) {
  static const std::regex valid(R"([A-Za-z0-9_][A-Za-z0-9_.\-]*)");
  if (!std::regex_match(name, valid)) {
    throw std::runtime_error("key name '" + name +
                             "' may hold only letters, digits, '_', '-' and '.' (no folders)");
  }
  const CurveKeyPair pair = generate_curve_key_pair();
  if (!fs::exists(dir)) {
    fs::create_directories(dir);
    fs::permissions(dir, fs::perms::owner_all);  // a new key folder is private
  }
  const std::string secret_file = (dir / (name + ".key")).string();
  const std::string public_file = (dir / (name + ".pub")).string();
  for (const std::string& file : {secret_file, public_file}) {
    struct stat info {};
    if (lstat(file.c_str(), &info) == 0 && !force) {
      throw std::runtime_error(file + " exists; pass --force to replace it");
    }
  }
  auto write = [](const std::string& file, const std::string& text, mode_t mode) {
    if (unlink(file.c_str()) != 0 && errno != ENOENT) {
      throw std::runtime_error(file + ": cannot replace it: " + std::strerror(errno));
    }
    // O_EXCL after the unlink: the file is new, so `mode` applies (less the umask) and nobody
    // can have it open already.
    const int fd = open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, mode);
    if (fd < 0) throw std::runtime_error(file + ": cannot create it: " + std::strerror(errno));
    const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
    const bool closed = close(fd) == 0;
    if (!ok || !closed) throw std::runtime_error(file + ": cannot write it");
  };
  write(secret_file,
        "# mocap CURVE secret key '" + name +
            "' (Z85). Keep it private (mode 0600); graph files name this file, never the key.\n" +
            pair.secret_key + "\n",
        0600);
  write(public_file,
        "# mocap CURVE public key '" + name + "' (Z85). Give it to the other end.\n" +
            pair.public_key + "\n",
        0644);
  return {secret_file, public_file, pair.public_key};
}

}  // namespace mocap::graph
