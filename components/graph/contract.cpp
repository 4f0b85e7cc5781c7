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
  outputs_.push_back(std::move(port));
}

void Contract::add_param(ParamSpec param) {
  if (find_param(param.name))
    throw std::logic_error("parameter '" + param.name + "' declared twice");
  if (param.fallback) check_range(param, *param.fallback);
  params_.push_back(std::move(param));
}

void Contract::network_socket(std::string endpoint_param, std::string bind_param) {
  if (network_) throw std::logic_error("network_socket() declared twice");
  param<std::string>("curve_server", "",
                     "CURVE: the binding end's key file (NAME.key where it binds, NAME.pub where "
                     "it connects); required beyond loopback (docs/security.md)");
  param<std::string>("curve_client", "",
                     "CURVE: the client key files (binding: NAME.pub or folders of *.pub, "
                     "comma-separated, the only clients let in; connecting: its own NAME.key)");
  network_ = NetworkSocket{std::move(endpoint_param), std::move(bind_param)};
}

}  // namespace mocap::graph
