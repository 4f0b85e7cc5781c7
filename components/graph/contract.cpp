#include "graph/contract.hpp"

#include <algorithm>
#include <stdexcept>

namespace mocap::graph {
namespace {

template <class Items>
int index_of(const Items& items, std::string_view name) {
  const auto it =
      std::find_if(items.begin(), items.end(), [&](const auto& item) { return item.name == name; });
  return it == items.end() ? -1 : static_cast<int>(it - items.begin());
}

}  // namespace

int Contract::input_index(std::string_view name) const { return index_of(inputs_, name); }
int Contract::output_index(std::string_view name) const { return index_of(outputs_, name); }

const ParamSpec* Contract::find_param(std::string_view name) const {
  const int i = index_of(params_, name);
  return i < 0 ? nullptr : &params_[static_cast<std::size_t>(i)];
}

void Contract::add_input(PortSpec port) {
  if (input_index(port.name) >= 0)
    throw std::logic_error("input '" + port.name + "' declared twice");
  inputs_.push_back(std::move(port));
}

void Contract::add_output(PortSpec port) {
  if (output_index(port.name) >= 0) {
    throw std::logic_error("output '" + port.name + "' declared twice");
  }
  if (!port.same_as.empty() && input_index(port.same_as) < 0) {
    throw std::logic_error("output '" + port.name + "' is the same as unknown input '" +
                           port.same_as + "' (declare inputs first)");
  }
  if (port.repeated) {
    const int input = input_index(port.per_edge_of);
    if (input < 0 || !inputs_[static_cast<std::size_t>(input)].repeated) {
      throw std::logic_error("repeated output '" + port.name + "' needs a repeated input, not '" +
                             port.per_edge_of + "' (declare inputs first)");
    }
  }
  outputs_.push_back(std::move(port));
}

void Contract::add_param(ParamSpec param) {
  if (find_param(param.name))
    throw std::logic_error("parameter '" + param.name + "' declared twice");
  if (!param.choices.empty() && param.type != ParamType::string)
    throw std::logic_error("parameter '" + param.name + "': only strings have choices");
  if (param.fallback) check_value(param, *param.fallback);
  params_.push_back(std::move(param));
}

bool Contract::is_joined(std::string_view input) const {
  return join_ && std::find(join_->ports.begin(), join_->ports.end(), input) != join_->ports.end();
}

void Contract::join(JoinSpec spec) {
  if (join_) throw std::logic_error("join() declared twice (one join per node)");
  if (spec.ports.empty()) throw std::logic_error("join() needs the inputs it joins");
  for (const std::string& port : spec.ports) {
    if (input_index(port) < 0) {
      throw std::logic_error("join() of unknown input '" + port + "' (declare inputs first)");
    }
  }
  param_choice("sync_by", spec.key == SyncKey::frame ? "frame" : "capture_time",
               {"frame", "capture_time"},
               "joined inputs: what the messages of one set share (frame: the frame number, "
               "offline; capture_time: capture times within sync_tolerance_ms, live)");
  param<std::int64_t>("sync_bound", spec.bound,
                      "joined inputs: messages held per input while their set waits for the "
                      "others (docs/graph-files.md, 'Joined inputs')",
                      {1, 1e6});
  param<double>("sync_tolerance_ms", spec.tolerance_ms,
                "joined inputs, capture_time: how far apart the capture times of one set may be",
                {0.0, 1e6});
  param<double>("sync_wait_ms", spec.wait_ms,
                "joined inputs: a set still incomplete after this wall-clock wait goes on "
                "partial; 0: no limit",
                {0.0, 1e7});
  param_choice("sync_late", spec.late == LateMessages::pass ? "pass" : "drop", {"pass", "drop"},
               "joined inputs: a message that comes after its set went on (sync_wait_ms, "
               "sync_bound) is passed on alone (pass) or counted and dropped (drop)");
  join_ = std::move(spec);
}

void Contract::network_socket(std::string endpoint_param, std::string bind_param) {
  if (network_) throw std::logic_error("network_socket() declared twice");
  param<std::string>("curve_server", "",
                     "CURVE: the binding end's key file (NAME.key where it binds, NAME.pub where "
                     "it connects); required beyond loopback (docs/security.md)");
  param_list<std::string>("curve_client", {},
                          "CURVE: the client key files (binding: NAME.pub or folders of *.pub, "
                          "the only clients let in; connecting: its own NAME.key)");
  network_ = NetworkSocket{std::move(endpoint_param), std::move(bind_param)};
}

}  // namespace mocap::graph
