#include "graph/set_limiter.hpp"

#include <stdexcept>

namespace mocap::graph {

SetLimiter::SetLimiter(std::size_t cameras, std::int64_t stall_ns)
    : stall_ns_(stall_ns), last_seen_(cameras) {}

std::optional<std::int64_t> SetLimiter::admit(const std::vector<bool>& present,
                                              std::int64_t capture_ns, bool stage_idle) {
  if (present.size() != last_seen_.size())
    throw std::invalid_argument("set limiter: one presence flag per camera expected");
  const auto number = static_cast<std::int64_t>(counts_.sets++);
  bool complete = true, waits_for_one_here = false;
  for (std::size_t i = 0; i < present.size(); ++i) {
    if (present[i]) continue;
    complete = false;
    const bool away = !last_seen_[i] || capture_ns - *last_seen_[i] > stall_ns_;
    waits_for_one_here = waits_for_one_here || !away;
  }
  for (std::size_t i = 0; i < present.size(); ++i) {
    if (present[i]) last_seen_[i] = capture_ns;
  }
  if (waits_for_one_here) {
    ++counts_.dropped_partial;
    return std::nullopt;
  }
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
         std::to_string(counts_.dropped_busy) + " dropped while the stage was busy, " +
         std::to_string(counts_.dropped_partial) + " partial";
}

}  // namespace mocap::graph
