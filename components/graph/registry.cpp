#include "graph/registry.hpp"

#include <algorithm>

namespace mocap::graph {

Registry& Registry::instance() {
  static Registry registry;
  return registry;
}

bool Registry::add(NodeType type) {
  std::lock_guard lock(mutex_);
  for (const auto& existing : types_) {
    if (existing->name == type.name) {
      problems_.push_back("node type '" + type.name + "' from " + origin_ +
                          " ignored: already registered by " + existing->origin);
      return false;
    }
  }
  type.origin = origin_;
  types_.push_back(std::make_unique<NodeType>(std::move(type)));
  return true;
}

const NodeType* Registry::find(std::string_view name) const {
  std::lock_guard lock(mutex_);
  for (const auto& type : types_) {
    if (type->name == name) return type.get();
  }
  return nullptr;
}

std::vector<const NodeType*> Registry::all() const {
  std::lock_guard lock(mutex_);
  std::vector<const NodeType*> result;
  for (const auto& type : types_) result.push_back(type.get());
  std::sort(result.begin(), result.end(),
            [](const NodeType* a, const NodeType* b) { return a->name < b->name; });
  return result;
}

std::vector<std::string> Registry::problems() const {
  std::lock_guard lock(mutex_);
  return problems_;
}

void Registry::set_origin(std::string origin) {
  std::lock_guard lock(mutex_);
  origin_ = std::move(origin);
}

}  // namespace mocap::graph
