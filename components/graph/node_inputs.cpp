#include "graph/node_inputs.hpp"

#include <stdexcept>

namespace mocap::graph {

SyncOptions sync_options(const std::map<std::string, ParamValue>& params, AtBound at_bound) {
  const auto value = [&](const char* name) -> const ParamValue& {
    const auto it = params.find(name);
    if (it == params.end()) throw std::logic_error(std::string("no parameter ") + name);
    return it->second;
  };
  const auto milliseconds = [](const ParamValue& v) {
    const double ms = std::holds_alternative<double>(v)
                          ? std::get<double>(v)
                          : static_cast<double>(std::get<std::int64_t>(v));
    return static_cast<std::int64_t>(ms * 1e6);
  };
  SyncOptions options;
  options.key =
      std::get<std::string>(value("sync_by")) == "frame" ? SyncKey::frame : SyncKey::capture_time;
  options.bound = static_cast<std::size_t>(std::get<std::int64_t>(value("sync_bound")));
  // Frame numbers match exactly: the tolerance is for capture times only (a node whose default
  // joins by capture time keeps its tolerance when a graph sets sync_by: frame).
  options.tolerance_ns =
      options.key == SyncKey::capture_time ? milliseconds(value("sync_tolerance_ms")) : 0;
  options.wait = std::chrono::nanoseconds(milliseconds(value("sync_wait_ms")));
  options.late =
      std::get<std::string>(value("sync_late")) == "drop" ? LateMessages::drop : LateMessages::pass;
  options.at_bound = at_bound;
  return options;
}

NodeInputs::NodeInputs(const Contract& contract, const std::vector<std::size_t>& counts,
                       std::vector<EdgePolicy> policies,
                       const std::map<std::string, ParamValue>& params, AtBound at_bound)
    : contract_(contract), inbox_(std::move(policies)), counts_(counts) {
  for (std::size_t input = 0; input < counts.size(); ++input) {
    first_.push_back(slot_input_.size());
    for (std::size_t i = 0; i < counts[input]; ++i) slot_input_.push_back(input);
  }
  if (inbox_.ports() != slot_input_.size()) {
    throw std::logic_error("node inputs: one edge policy per connected edge expected");
  }
  slot_sync_.assign(slot_input_.size(), -1);
  for (std::size_t slot = 0; slot < slot_input_.size(); ++slot) {
    if (!contract.is_joined(contract.inputs()[slot_input_[slot]].name)) continue;
    slot_sync_[slot] = static_cast<int>(sync_slot_.size());
    sync_slot_.push_back(slot);
  }
  if (!sync_slot_.empty()) {
    sync_ = std::make_unique<Synchronizer>(sync_slot_.size(), sync_options(params, at_bound));
  }
  readable_.assign(slot_input_.size(), true);
  current_.resize(slot_input_.size());
}

std::vector<NodeInputs::SlotName> NodeInputs::joined_slots() const {
  std::vector<SlotName> names;
  for (std::size_t slot : sync_slot_) {
    const PortSpec& port = contract_.inputs()[slot_input_[slot]];
    names.push_back({port.name, slot - first_[slot_input_[slot]], port.repeated});
  }
  return names;
}

NodeInputs::Step NodeInputs::next(bool wait) {
  clear();
  while (true) {
    const auto now = Synchronizer::Clock::now();
    if (sync_ && sync_->pop(now, set_)) {
      for (std::size_t k = 0; k < sync_slot_.size(); ++k) {
        current_[sync_slot_[k]] = std::move(set_.packets[k]);
      }
      has_call_ = in_set_ = true;
      return Step::call;
    }
    if (ended_ == slots() && (!sync_ || sync_->finished())) return Step::ended;
    for (std::size_t slot = 0; slot < slots(); ++slot) {
      readable_[slot] =
          slot_sync_[slot] < 0 || sync_->readable(static_cast<std::size_t>(slot_sync_[slot]));
    }
    if (wait) {
      Inbox::Waited waited = inbox_.pop(readable_, sync_ ? sync_->deadline() : std::nullopt);
      if (waited.closed) return Step::closed;
      if (waited.delivery && deliver(std::move(*waited.delivery))) return Step::call;
    } else {
      std::optional<Inbox::Delivery> delivery = inbox_.try_pop(readable_);
      if (!delivery) return Step::nothing;
      if (deliver(std::move(*delivery))) return Step::call;
    }
  }
}

bool NodeInputs::deliver(Inbox::Delivery delivery) {
  const int joined = slot_sync_[delivery.port];
  if (delivery.packet.is_end_of_stream()) {
    if (!delivery.packet.header().stream.empty()) received_end_ = delivery.packet.header();
    ++ended_;
    if (joined >= 0) sync_->end(static_cast<std::size_t>(joined));
    return false;
  }
  ++received_;
  if (joined >= 0) {
    sync_->push(static_cast<std::size_t>(joined), std::move(delivery.packet),
                Synchronizer::Clock::now());
    return false;
  }
  single_slot_ = delivery.port;
  current_[delivery.port] = std::move(delivery.packet);
  has_call_ = true;
  in_set_ = false;
  return true;
}

void NodeInputs::clear() {
  if (!has_call_) return;
  for (Packet& packet : current_) packet = Packet{};
  has_call_ = in_set_ = false;
}

const Packet* NodeInputs::find(std::string_view port, std::size_t index) const {
  if (!has_call_) return nullptr;
  const int input = contract_.input_index(port);
  if (input < 0 || index >= counts_[static_cast<std::size_t>(input)]) return nullptr;
  const Packet& packet = current_[slot(static_cast<std::size_t>(input), index)];
  return packet.message ? &packet : nullptr;
}

std::size_t NodeInputs::count(std::string_view port) const {
  const int input = contract_.input_index(port);
  return input < 0 ? 0 : counts_[static_cast<std::size_t>(input)];
}

std::string_view NodeInputs::port_name() const {
  if (!has_call_) return {};
  if (!in_set_) return contract_.inputs()[slot_input_[single_slot_]].name;
  for (std::size_t slot = 0; slot < slots(); ++slot) {
    if (current_[slot].message) return contract_.inputs()[slot_input_[slot]].name;
  }
  return {};
}

const Header* NodeInputs::header() const {
  if (!has_call_) return nullptr;
  if (!in_set_) return &current_[single_slot_].header();
  for (const Packet& packet : current_) {
    if (packet.message) return &packet.header();
  }
  return nullptr;
}

}  // namespace mocap::graph
