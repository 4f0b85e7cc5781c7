#pragma once
// The input side of a node: one bounded queue per input port, all behind one lock so the node's
// thread can wait for "any input". Each port has its edge's policy:
//   blocking(N)     the producer waits while N messages are queued: nothing is ever lost
//   latest          one slot; a new message replaces the waiting one (counted as a drop)
//   drop_oldest(N)  N slots; when full the oldest waiting message is dropped (counted)
// End of stream is never dropped and never waits: it is always queued behind the data.

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <vector>

#include "graph/graph_spec.hpp"
#include "graph/packet.hpp"
#include "graph/stats.hpp"

namespace mocap::graph {

class Inbox {
 public:
  explicit Inbox(std::vector<EdgePolicy> ports);

  // Queues `packet` on `port` following the port's policy. Returns false when the inbox is closed
  // (its node stopped or failed): the packet is discarded and counted as a drop.
  bool push(std::size_t port, Packet packet);

  struct Delivery {
    std::size_t port;
    Packet packet;
  };
  // Waits for the oldest waiting message of any port; nullopt once the inbox is closed.
  std::optional<Delivery> pop();

  // Waits for the oldest waiting message of the ports marked in `readable` (a port left out keeps
  // its messages, and a blocking edge into it fills and makes its producer wait), until
  // `deadline` (none: no limit). `closed` says the inbox was closed; otherwise no delivery means
  // the deadline passed.
  struct Waited {
    std::optional<Delivery> delivery;
    bool closed = false;
  };
  Waited pop(const std::vector<bool>& readable,
             std::optional<std::chrono::steady_clock::time_point> deadline);
  // Without waiting: the oldest message of the readable ports, if any.
  std::optional<Delivery> try_pop(const std::vector<bool>& readable);
  std::size_t ports() const { return ports_.size(); }

  // The node will not read any more: wakes every waiter, further pushes are discarded.
  void close();

  std::uint64_t drops() const;
  std::size_t depth() const;
  // Nothing queued, and the node came back for more since it last took a message (it is not
  // processing one): what Context::output_idle asks of each consumer.
  bool idle() const;
  std::size_t max_depth() const;
  // How long the messages taken lately waited in this inbox (push to pop), {p50, p95} in
  // microseconds: a stage that cannot keep up shows here as a growing wait.
  std::array<double, 2> wait_percentiles_us() const { return wait_.percentiles_us(); }

 private:
  struct Item {
    Packet packet;
    std::uint64_t arrival;
    std::chrono::steady_clock::time_point pushed;
  };
  // The port whose front is oldest among the readable ones; ports_.size() when none.
  std::size_t oldest(const std::vector<bool>* readable) const;
  Delivery take(std::size_t port);

  struct Port {
    EdgePolicy policy;
    std::deque<Item> items;
    std::size_t data_items = 0;  // items that are not end of stream
  };

  mutable std::mutex mutex_;
  std::condition_variable readable_, writable_;
  std::vector<Port> ports_;
  std::uint64_t next_arrival_ = 0;
  std::uint64_t drops_ = 0;
  std::size_t depth_ = 0, max_depth_ = 0;
  bool closed_ = false;
  bool taken_ = false;  // a message was taken and the node has not asked for the next yet
  LatencyWindow wait_;
};

}  // namespace mocap::graph
