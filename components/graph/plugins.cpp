#include "graph/plugins.hpp"

#include <dlfcn.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "graph/registry.hpp"

namespace mocap::graph {
namespace {

struct CloseLibrary {
  void operator()(void* handle) const { dlclose(handle); }
};
using LibraryHandle = std::unique_ptr<void, CloseLibrary>;

std::string last_dl_error() {
  const char* message = dlerror();
  return message ? message : "unknown error";
}

}  // namespace

void check_plugin_path_safe(const std::string& path) {
  struct stat info {};
  if (stat(path.c_str(), &info) != 0) return;  // dlopen or the listing names what is missing
  const char* what = S_ISDIR(info.st_mode) ? "plugin folder " : "plugin ";
  // Sticky folders (/tmp) let others add files too, so they are refused like any other.
  if (info.st_mode & (S_IWGRP | S_IWOTH)) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(info.st_mode & 07777));
    throw std::runtime_error(std::string(what) + path + " is writable by " +
                             ((info.st_mode & S_IWOTH) ? "others" : "its group") + " (mode " +
                             mode +
                             "): anyone who can write it could run code in this program; "
                             "refused (chmod go-w it)");
  }
  if (info.st_uid != 0 && info.st_uid != geteuid()) {
    throw std::runtime_error(std::string(what) + path + " belongs to another user (uid " +
                             std::to_string(info.st_uid) +
                             "), who could change it to run code in this program; refused");
  }
}

namespace {

using AbiFunction = const char* (*)();

AbiFunction plugin_abi(void* handle, const std::string& path) {
  const auto abi = reinterpret_cast<AbiFunction>(dlsym(handle, "mocap_plugin_abi"));
  if (!abi) {
    throw std::runtime_error("plugin " + path + ": not a mocap plugin (no MOCAP_PLUGIN())");
  }
  return abi;
}

}  // namespace

void load_plugin(const std::string& path) {
  const std::string canonical = std::filesystem::weakly_canonical(path).string();
  // Already loaded (RTLD_NOLOAD only succeeds for a library in the process): its node types are
  // registered, if it is a plugin at all; a library loaded for another reason is still refused.
  if (LibraryHandle loaded{dlopen(canonical.c_str(), RTLD_NOW | RTLD_NOLOAD)}) {
    plugin_abi(loaded.get(), path);
    return;
  }

  // Neither the file nor the folder it is in may be open to others: they could swap the code.
  check_plugin_path_safe(canonical);
  check_plugin_path_safe(std::filesystem::path(canonical).parent_path().string());

  // Registration runs in the library's static initialisers, inside dlopen.
  Registry::instance().set_origin(canonical);
  LibraryHandle handle{dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL)};
  Registry::instance().set_origin("built-in");
  if (!handle) throw std::runtime_error("plugin " + path + ": " + last_dl_error());

  const AbiFunction abi = plugin_abi(handle.get(), path);
  if (std::strcmp(abi(), kPluginAbi) != 0) {
    throw std::runtime_error("plugin " + path + ": built for " + abi() + ", this program is " +
                             kPluginAbi);
  }
  // Node types of the plugin stay registered for the life of the process, so it stays loaded.
  [[maybe_unused]] void* kept = handle.release();
}

void load_plugins_from(const std::string& file_or_directory) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(file_or_directory)) {
    load_plugin(file_or_directory);
    return;
  }
  check_plugin_path_safe(fs::weakly_canonical(file_or_directory).string());
  std::vector<fs::path> libraries;
  for (const auto& entry : fs::directory_iterator(file_or_directory)) {
    if (entry.is_regular_file() && entry.path().extension() == ".so")
      libraries.push_back(entry.path());
  }
  std::sort(libraries.begin(), libraries.end());  // a stable order makes conflicts reproducible
  for (const auto& library : libraries) load_plugin(library.string());
}

void load_plugins_from_environment() {
  const char* value = std::getenv("MOCAP_PLUGIN_PATH");
  if (!value) return;
  std::string paths = value;
  std::size_t start = 0;
  while (start <= paths.size()) {
    const std::size_t end = std::min(paths.find(':', start), paths.size());
    const std::string entry = paths.substr(start, end - start);
    if (!entry.empty() && std::filesystem::exists(entry)) load_plugins_from(entry);
    start = end + 1;
  }
}

}  // namespace mocap::graph
