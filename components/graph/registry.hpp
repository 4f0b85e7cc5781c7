#pragma once
// Node types by name. Built-in types register themselves with MOCAP_REGISTER_NODE when the program
// starts; plugins (shared libraries, see plugins.hpp) do the same when they are loaded.
// The registry is the framework's only process-wide mutable state.

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "graph/contract.hpp"
#include "graph/node.hpp"

namespace mocap::graph {

struct NodeType {
  std::string name;  // stable, dotted: "detect.movenet", "sink.bvh"
  Contract contract;
  std::function<std::unique_ptr<Node>()> create;
  std::string origin;  // "built-in" or the plugin file that registered it
};

class Registry {
 public:
  static Registry& instance();

  // A second type with the same name is refused; the conflict is kept in problems().
  bool add(NodeType type);
  const NodeType* find(std::string_view name) const;
  std::vector<const NodeType*> all() const;  // sorted by name
  std::vector<std::string> problems() const;

  // Types added while a plugin loads are tagged with its file name.
  void set_origin(std::string origin);

 private:
  Registry() = default;
  mutable std::mutex mutex_;
  std::vector<std::unique_ptr<NodeType>> types_;
  std::vector<std::string> problems_;
  std::string origin_ = "built-in";
};

template <class N>
bool register_node(std::string_view name) {
  NodeType type{std::string(name), {}, [] { return std::make_unique<N>(); }, {}};
  N::contract(type.contract);
  return Registry::instance().add(std::move(type));
}

// Bumped whenever Node, Context, Contract or the message types change layout; a plugin built
// against another version is refused instead of crashing.
inline constexpr const char* kPluginAbi = "mocap-graph-abi-3";

}  // namespace mocap::graph

#define MOCAP_GRAPH_CONCAT_INNER(a, b) a##b
#define MOCAP_GRAPH_CONCAT(a, b) MOCAP_GRAPH_CONCAT_INNER(a, b)

// Registers NodeClass under `type_name` at start-up (or when its plugin is loaded).
#define MOCAP_REGISTER_NODE(type_name, NodeClass)                               \
  namespace {                                                                   \
  [[maybe_unused]] const bool MOCAP_GRAPH_CONCAT(mocap_registered_, __LINE__) = \
      ::mocap::graph::register_node<NodeClass>(type_name);                      \
  }

// Marks a shared library as a mocap plugin; put it once in one of the plugin's files.
#define MOCAP_PLUGIN()                                                               \
  extern "C" __attribute__((visibility("default"))) const char* mocap_plugin_abi() { \
    return ::mocap::graph::kPluginAbi;                                               \
  }
