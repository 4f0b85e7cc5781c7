#pragma once
// Plugins: shared libraries that register more node types when loaded. They are found in the
// directories of MOCAP_PLUGIN_PATH (colon-separated, every *.so in them) and in a graph file's
// `plugins:` list (files or directories, relative to the graph file).

#include <string>
#include <vector>

namespace mocap::graph {

// Loads one plugin file (once per process; loading it again is a no-op). Throws std::runtime_error
// naming the file when it cannot be loaded, is not a mocap plugin or was built for another ABI.
void load_plugin(const std::string& path);
// Loads every *.so of a directory, or the file itself.
void load_plugins_from(const std::string& file_or_directory);
// Loads everything MOCAP_PLUGIN_PATH names.
void load_plugins_from_environment();

}  // namespace mocap::graph
