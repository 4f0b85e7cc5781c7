#include "graph/set_limiter.hpp"

namespace mocap::graph {

std::optional<std::int64_t> SetLimiter::admit(bool complete, bool stage_idle) {
  const auto number = static_cast<std::int64_t>(counts_.sets++);
  if (!stage_idle) {
    ++counts_.dropped_busy;
    return std::nullopt;
  }
  ++counts_.passed;
  if (complete) ++counts_.passed_complete;
  return number;
}

std::string SetLimiter::describe() const {
  return "passed " + std::to_string(counts_.passed) + " of " + std::to_string(counts_.sets) +
         " sets (" + std::to_string(counts_.passed_complete) + " complete), " +
         std::to_string(counts_.dropped_busy) + " dropped while the stage was busy";
}

}  // namespace mocap::graph
