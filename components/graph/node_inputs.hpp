#pragma once
// The input side of a running node, shared by the runtime and the test harness (harness.hpp), so
// that a node tested alone is fed exactly as in a graph: one inbox queue per edge ("slot"; a
// repeated input has one per edge), the synchroniser of the joined inputs, and what one process()
// call sees (a single message of an input that is not joined, or a set of the joined ones).

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "graph/contract.hpp"
#include "graph/inbox.hpp"
#include "graph/params.hpp"
#include "graph/synchronizer.hpp"

namespace mocap::graph {

// The synchroniser settings of a joined node from its resolved parameters (sync_*).
SyncOptions sync_options(const std::map<std::string, ParamValue>& params, AtBound at_bound);

class NodeInputs {
 public:
  // `counts`: edges wired to each contract input (ResolvedNode::input_counts); `policies`: each
  // edge's policy, slot by slot (input 0's edges first, by index). `params` holds the node's
  // resolved parameters (the sync_* ones are read when the contract joins inputs).
  NodeInputs(const Contract& contract, const std::vector<std::size_t>& counts,
             std::vector<EdgePolicy> policies, const std::map<std::string, ParamValue>& params,
             AtBound at_bound);

  Inbox& inbox() { return inbox_; }
  const Inbox& inbox() const { return inbox_; }
  std::size_t slots() const { return slot_input_.size(); }
  // The slot of edge `index` of contract input `input`.
  std::size_t slot(std::size_t input, std::size_t index) const { return first_[input] + index; }

  enum class Step {
    call,     // current() holds the next call for process()
    ended,    // every input has ended and everything was passed on
    closed,   // the inbox was closed (the node stops)
    nothing,  // without waiting: nothing is ready yet
  };
  // The next call; `wait` false looks without blocking (the harness in the test's thread).
  Step next(bool wait);
  // Forgets the current call (its messages are released).
  void clear();

  // --- the current call, for the node's Context
  const Packet* find(std::string_view port, std::size_t index) const;
  std::size_t count(std::string_view port) const;
  bool in_set() const { return in_set_; }
  bool has_call() const { return has_call_; }
  std::string_view port_name() const;
  const Header* header() const;
  // The messages of the current call, slot by slot (absent ones hold no message).
  const std::vector<Packet>& current() const { return current_; }

  std::uint64_t received() const { return received_; }  // data messages taken in
  std::size_t connected() const { return slots(); }
  // The header of the last end of stream that named its stream (passed on by nodes that sent
  // nothing themselves).
  const Header& received_end() const { return received_end_; }
  const Synchronizer* synchronizer() const { return sync_.get(); }
  // The input and index of each slot joined by the synchroniser, in its order.
  struct SlotName {
    std::string port;
    std::size_t index;
    bool repeated;
  };
  std::vector<SlotName> joined_slots() const;

 private:
  bool deliver(Inbox::Delivery delivery);  // true when it makes a call

  const Contract& contract_;
  Inbox inbox_;
  std::vector<std::size_t> first_, counts_;  // per contract input: first slot, slot count
  std::vector<std::size_t> slot_input_;      // per slot: its contract input
  std::vector<int> slot_sync_;               // per slot: its synchroniser input, or -1
  std::vector<std::size_t> sync_slot_;       // per synchroniser input: its slot
  std::unique_ptr<Synchronizer> sync_;
  std::vector<bool> readable_;
  SyncSet set_;

  std::vector<Packet> current_;
  bool has_call_ = false, in_set_ = false;
  std::size_t single_slot_ = 0;
  std::size_t ended_ = 0;
  std::uint64_t received_ = 0;
  Header received_end_;
};

}  // namespace mocap::graph
