#include "graph/synchronizer.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace mocap::graph {
namespace {

// b - a for b >= a without signed overflow (keys come from outside: any int64 is possible).
std::uint64_t distance(std::int64_t a, std::int64_t b) {
  return static_cast<std::uint64_t>(b) - static_cast<std::uint64_t>(a);
}

std::int64_t saturated_sum(std::int64_t a, std::int64_t b) {
  std::int64_t sum = 0;
  return __builtin_add_overflow(a, b, &sum) ? std::numeric_limits<std::int64_t>::max() : sum;
}

}  // namespace

bool SyncSet::complete() const {
  return !late && std::all_of(packets.begin(), packets.end(),
                              [](const Packet& p) { return p.message != nullptr; });
}

Synchronizer::Synchronizer(std::size_t inputs, SyncOptions options)
    : options_(options), inputs_(inputs) {
  if (inputs == 0) throw std::invalid_argument("a synchroniser needs at least one input");
  if (options_.bound == 0) throw std::invalid_argument("a synchroniser's bound must be at least 1");
  if (options_.tolerance_ns < 0) throw std::invalid_argument("a negative sync tolerance");
  stats_.inputs.resize(inputs);
}

std::int64_t Synchronizer::key_of(const Packet& packet) const {
  return options_.key == SyncKey::frame ? packet.header().frame : packet.header().capture_ns;
}

void Synchronizer::push(std::size_t index, Packet packet, Clock::time_point now) {
  Input& input = inputs_.at(index);
  SyncInputStats& stats = stats_.inputs[index];
  const std::int64_t key = key_of(packet);
  ++stats.received;
  if (input.last_key && key < *input.last_key) restart();  // the stream went back
  input.last_key = key;
  if (input.late_to && key <= *input.late_to) {
    // Its set went on without it (a wait limit or the bound): counted, passed on alone or dropped.
    ++stats.late;
    if (options_.late == LateMessages::drop) {
      ++stats.late_dropped;
      return;
    }
    SyncSet set;
    set.packets.resize(inputs_.size());
    set.packets[index] = std::move(packet);
    set.key = key;
    set.late = true;
    ready_.push_back(std::move(set));
    ++stats_.sets;
    return;
  }
  input.held.push_back({std::move(packet), key, now});
  stats.held = input.held.size();
  stats.max_held = std::max(stats.max_held, stats.held);
}

void Synchronizer::end(std::size_t index) {
  inputs_.at(index).ended = true;
  stats_.inputs[index].ended = true;
}

std::optional<std::int64_t> Synchronizer::anchor() const {
  std::optional<std::int64_t> oldest;
  for (const Input& input : inputs_) {
    if (!input.held.empty() && (!oldest || input.held.front().key < *oldest)) {
      oldest = input.held.front().key;
    }
  }
  return oldest;
}

bool Synchronizer::member(const Input& input, std::int64_t anchor) const {
  return !input.held.empty() && distance(anchor, input.held.front().key) <=
                                    static_cast<std::uint64_t>(options_.tolerance_ns);
}

// An input without a member can no longer give one: it ended, it holds a newer message, or the
// newest message it sent is already past the set (the next one will be newer still).
bool Synchronizer::settled(const Input& input, std::int64_t anchor) const {
  return input.ended || !input.held.empty() ||
         (input.last_key && *input.last_key >= anchor &&
          distance(anchor, *input.last_key) >= static_cast<std::uint64_t>(options_.tolerance_ns));
}

bool Synchronizer::pop(Clock::time_point now, SyncSet& set) {
  if (!ready_.empty()) {
    set = std::move(ready_.front());
    ready_.pop_front();
    return true;
  }
  const std::optional<std::int64_t> key = anchor();
  if (!key) return false;
  bool can_complete = false, at_bound = false;
  Clock::time_point first = now;
  for (const Input& input : inputs_) {
    if (member(input, *key)) {
      first = std::min(first, input.held.front().arrival);
    } else if (!settled(input, *key)) {
      can_complete = true;
    }
    at_bound = at_bound || input.held.size() >= options_.bound;
  }
  const bool waited_enough = options_.wait.count() > 0 && now - first >= options_.wait;
  const bool bound_passes = at_bound && options_.at_bound == AtBound::pass_partial;
  if (can_complete && !waited_enough && !bound_passes) return false;
  take(*key, set);
  return true;
}

void Synchronizer::take(std::int64_t key, SyncSet& set) {
  set.packets.resize(inputs_.size());
  set.key = key;
  set.late = false;
  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    Input& input = inputs_[i];
    SyncInputStats& stats = stats_.inputs[i];
    if (member(input, key)) {
      set.packets[i] = std::move(input.held.front().packet);
      input.held.pop_front();
      stats.held = input.held.size();
    } else {
      set.packets[i] = Packet{};
      ++stats.missing;
      // A message of this input keyed within the set's reach would now come too late.
      const std::int64_t reach = saturated_sum(key, options_.tolerance_ns);
      input.late_to = input.late_to ? std::max(*input.late_to, reach) : reach;
    }
  }
  ++stats_.sets;
  if (set.complete()) ++stats_.complete;
  count_skew(set);
}

void Synchronizer::count_skew(const SyncSet& set) {
  std::int64_t oldest = std::numeric_limits<std::int64_t>::max();
  std::int64_t newest = std::numeric_limits<std::int64_t>::min();
  std::size_t timed = 0;
  for (const Packet& packet : set.packets) {
    if (!packet.message || packet.header().capture_ns == 0) continue;  // 0: no capture time
    oldest = std::min(oldest, packet.header().capture_ns);
    newest = std::max(newest, packet.header().capture_ns);
    ++timed;
  }
  if (timed < 2) return;
  // Saturated: capture times come from outside.
  const std::int64_t skew = static_cast<std::int64_t>(
      std::min<std::uint64_t>(distance(oldest, newest), std::numeric_limits<std::int64_t>::max()));
  skews_[stats_.skew_sets % kSkewSamples] = skew;
  ++stats_.skew_sets;
  skew_max_ns_ = std::max(skew_max_ns_, skew);
}

SyncStats Synchronizer::stats() const {
  SyncStats stats = stats_;
  if (stats.skew_sets == 0) return stats;
  const std::size_t n =
      static_cast<std::size_t>(std::min<std::uint64_t>(stats.skew_sets, kSkewSamples));
  const std::vector<std::int64_t> skews(skews_.begin(),
                                        skews_.begin() + static_cast<std::ptrdiff_t>(n));
  stats.skew_p50_ms = percentile(skews, 50) / 1e6;
  stats.skew_p95_ms = percentile(skews, 95) / 1e6;
  stats.skew_max_ms = static_cast<double>(skew_max_ns_) / 1e6;
  return stats;
}

// Everything held goes on as it is, oldest first, and joining starts afresh.
void Synchronizer::restart() {
  ++stats_.restarts;
  while (const std::optional<std::int64_t> key = anchor()) take(*key, ready_.emplace_back());
  for (Input& input : inputs_) {
    input.last_key.reset();
    input.late_to.reset();
  }
}

bool Synchronizer::readable(std::size_t input) const {
  return inputs_.at(input).held.size() < options_.bound;
}

std::optional<Synchronizer::Clock::time_point> Synchronizer::deadline() const {
  if (options_.wait.count() <= 0) return std::nullopt;
  const std::optional<std::int64_t> key = anchor();
  if (!key) return std::nullopt;
  std::optional<Clock::time_point> first;
  for (const Input& input : inputs_) {
    if (member(input, *key) && (!first || input.held.front().arrival < *first)) {
      first = input.held.front().arrival;
    }
  }
  return *first + options_.wait;
}

bool Synchronizer::finished() const {
  return ready_.empty() && std::all_of(inputs_.begin(), inputs_.end(), [](const Input& input) {
           return input.ended && input.held.empty();
         });
}

}  // namespace mocap::graph
