#pragma once
// Plugins: shared libraries that register more node types when loaded. They are found in the
// directories of MOCAP_PLUGIN_PATH (colon-separated, every *.so in them) and in a graph file's
// `plugins:` list (files or directories, relative to the graph file), nowhere else. A plugin file,
// or the folder it is in or listed from, that others can write to is refused.

#include <string>
#include <vector>

namespace mocap::graph {

// Throws std::runtime_error naming `path` (a plugin file or folder) when others could change it:
// writable by group or others, or owned by a user other than root and this one.
void check_plugin_path_safe(const std::string& path);
// Loads one plugin file (once per process; loading it again is a no-op). Throws std::runtime_error
// naming the file when it cannot be loaded, is not a mocap plugin or was built for another ABI.
void load_plugin(const std::string& path);
// Loads every *.so of a directory, or the file itself.
void load_plugins_from(const std::string& file_or_directory);
// Loads everything MOCAP_PLUGIN_PATH names.
void load_plugins_from_environment();

}  // namespace mocap::graph
