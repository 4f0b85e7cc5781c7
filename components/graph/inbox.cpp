#include "graph/inbox.hpp"

#include <algorithm>

namespace mocap::graph {

Inbox::Inbox(std::vector<EdgePolicy> ports) {
  for (const EdgePolicy& policy : ports) ports_.push_back(Port{policy, {}, 0});
}

bool Inbox::push(std::size_t port_index, Packet packet) {
  std::unique_lock lock(mutex_);
  Port& port = ports_.at(port_index);
  const bool eos = packet.is_end_of_stream();
  if (!eos) {
    if (port.policy.kind == PolicyKind::blocking) {
      writable_.wait(lock, [&] { return closed_ || port.data_items < port.policy.capacity; });
    } else if (port.data_items >= port.policy.capacity && !closed_) {
      // Lossy: make room by dropping the oldest waiting data (for latest, the only one).
      const auto oldest = std::find_if(port.items.begin(), port.items.end(),
                                       [](const Item& i) { return !i.packet.is_end_of_stream(); });
      port.items.erase(oldest);
      --port.data_items;
      --depth_;
      ++drops_;
    }
  }
  if (closed_) {
    ++drops_;
    return false;
  }
  port.items.push_back(Item{std::move(packet), next_arrival_++, std::chrono::steady_clock::now()});
  if (!eos) ++port.data_items;
  max_depth_ = std::max(max_depth_, ++depth_);
  lock.unlock();
  readable_.notify_one();
  return true;
}

std::size_t Inbox::oldest(const std::vector<bool>* readable) const {
  std::size_t best = ports_.size();
  for (std::size_t i = 0; i < ports_.size(); ++i) {
    const Port& port = ports_[i];
    if (port.items.empty() || (readable && !(*readable)[i])) continue;
    if (best == ports_.size() || port.items.front().arrival < ports_[best].items.front().arrival) {
      best = i;
    }
  }
  return best;
}

// Called with the lock held; notifies producers after unlocking is left to the caller.
Inbox::Delivery Inbox::take(std::size_t index) {
  Port& port = ports_[index];
  if (!port.items.front().packet.is_end_of_stream()) {
    wait_.add(std::chrono::duration_cast<std::chrono::nanoseconds>(
                  std::chrono::steady_clock::now() - port.items.front().pushed)
                  .count());
  }
  Delivery delivery{index, std::move(port.items.front().packet)};
  port.items.pop_front();
  if (!delivery.packet.is_end_of_stream()) --port.data_items;
  --depth_;
  taken_ = true;
  return delivery;
}

std::optional<Inbox::Delivery> Inbox::pop() {
  std::unique_lock lock(mutex_);
  taken_ = false;  // asking for the next: done with the last
  readable_.wait(lock, [&] { return closed_ || depth_ > 0; });
  if (closed_) return std::nullopt;
  Delivery delivery = take(oldest(nullptr));
  lock.unlock();
  writable_.notify_all();  // producers of different ports share the condition
  return delivery;
}

Inbox::Waited Inbox::pop(const std::vector<bool>& readable,
                         std::optional<std::chrono::steady_clock::time_point> deadline) {
  std::unique_lock lock(mutex_);
  taken_ = false;
  const auto ready = [&] { return closed_ || oldest(&readable) < ports_.size(); };
  if (deadline) {
    if (!readable_.wait_until(lock, *deadline, ready)) return {};
  } else {
    readable_.wait(lock, ready);
  }
  if (closed_) return {std::nullopt, true};
  Delivery delivery = take(oldest(&readable));
  lock.unlock();
  writable_.notify_all();
  return {std::move(delivery), false};
}

std::optional<Inbox::Delivery> Inbox::try_pop(const std::vector<bool>& readable) {
  std::unique_lock lock(mutex_);
  taken_ = false;
  const std::size_t port = oldest(&readable);
  if (closed_ || port == ports_.size()) return std::nullopt;
  Delivery delivery = take(port);
  lock.unlock();
  writable_.notify_all();
  return delivery;
}

void Inbox::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
    for (Port& port : ports_) {
      drops_ += port.data_items;
      port.items.clear();
      port.data_items = 0;
    }
    depth_ = 0;
  }
  readable_.notify_all();
  writable_.notify_all();
}

std::uint64_t Inbox::drops() const {
  std::lock_guard lock(mutex_);
  return drops_;
}

std::size_t Inbox::depth() const {
  std::lock_guard lock(mutex_);
  return depth_;
}

bool Inbox::idle() const {
  std::lock_guard lock(mutex_);
  return closed_ || (depth_ == 0 && !taken_);  // a closed inbox discards: nothing to wait for
}

std::size_t Inbox::max_depth() const {
  std::lock_guard lock(mutex_);
  return max_depth_;
}

}  // namespace mocap::graph
