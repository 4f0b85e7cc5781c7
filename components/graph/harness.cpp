#include "graph/harness.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <utility>

#include "core/input_error.hpp"
#include "graph/node_inputs.hpp"
#include "graph/registry.hpp"
#include "graph/validation.hpp"

namespace mocap::graph {

using Clock = std::chrono::steady_clock;

struct Harness::Impl final : public Context {
  Impl(const std::string& type_name, const std::map<std::string, std::string>& texts,
       HarnessOptions options);

  // --- Context
  const std::string& node_name() const override { return name; }
  std::string_view input_port() const override { return inputs->port_name(); }
  const Packet* find_input(std::string_view port, std::size_t index) const override {
    return inputs->find(port, index);
  }
  std::size_t input_count(std::string_view port) const override { return inputs->count(port); }
  bool in_set() const override { return inputs->in_set(); }
  const Header* input_header() const override { return inputs->header(); }
  using Context::send_packet;
  void send_packet(std::string_view port, std::size_t index, Packet packet) override;
  bool output_idle(std::string_view port, std::size_t index) const override {
    const std::lock_guard lock(mutex);
    return !busy_outputs.count({std::string(port), index});
  }
  void count_drop() override { ++own_drops; }
  void report_status(std::string text) override {
    const std::lock_guard lock(mutex);
    status = std::move(text);
  }
  void finish() override { source_finished = true; }
  bool stop_requested() const override { return stopping; }
  bool sleep_for(std::chrono::nanoseconds duration) override {
    std::unique_lock lock(mutex);
    return !wake.wait_for(lock, duration, [&] { return stopping.load(); });
  }
  GraphStats stats() const override {
    GraphStats graph;
    graph.graph = "harness";
    graph.nodes.push_back(snapshot());
    return graph;
  }
  const ParamValue& param_value(std::string_view param) const override {
    const auto it = params.find(std::string(param));
    if (it == params.end()) {
      throw std::logic_error("node '" + name + "': parameter '" + std::string(param) +
                             "' is not in the contract of " + type->name);
    }
    return it->second;
  }

  void open_once() {
    if (opened) return;
    opened = true;  // a failing open() is not retried; close() is not called after it
    state = 1;
    try {
      instance->open(*this);
    } catch (...) {
      failed_open = true;
      fail();
      throw;
    }
  }
  void timed_process() {
    const auto start = Clock::now();
    try {
      instance->process(*this);
    } catch (...) {
      inputs->clear();
      fail();
      throw;
    }
    latency.add(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start).count());
    inputs->clear();
    in = inputs->received();
    publish_sync();
  }
  // The synchroniser's counters, copied where the test's thread may read them.
  void publish_sync() {
    const Synchronizer* sync = inputs->synchronizer();
    if (!sync) return;
    const auto slots = inputs->joined_slots();
    const std::lock_guard lock(mutex);
    sync_copy = sync->stats();
    for (std::size_t i = 0; i < slots.size(); ++i) {
      sync_copy.inputs[i].name =
          indexed_port(slots[i].port, slots[i].repeated ? static_cast<long>(slots[i].index) : -1);
    }
  }
  void close_once() {
    if (closed) return;
    closed = true;
    inputs->inbox().close();
    in = inputs->received();
    publish_sync();
    if (opened && !failed_open) instance->close(*this);
    const std::lock_guard lock(mutex);
    for (std::size_t i = 0; i < ended_outputs.size(); ++i) ended_outputs[i] = true;
    if (state != 3) state = 2;
  }
  void fail() {
    state = 3;
    inputs->inbox().close();
  }
  NodeStats snapshot() const;
  std::size_t slot_of(std::string_view input, std::size_t index) const;

  const NodeType* type = nullptr;
  std::string name;
  std::map<std::string, ParamValue> params;
  std::unique_ptr<Node> instance;
  std::unique_ptr<NodeInputs> inputs;
  std::vector<bool> slot_ended;  // ends pushed by the test

  mutable std::mutex mutex;  // outputs, status: the node's thread writes, the test reads
  std::condition_variable wake;
  std::vector<std::vector<std::vector<Packet>>> sent;  // per output port, per stream
  std::set<std::pair<std::string, std::size_t>> busy_outputs;
  std::vector<bool> ended_outputs;
  std::string status;
  SyncStats sync_copy;

  std::atomic<std::uint64_t> in{0}, out{0}, own_drops{0};
  std::atomic<int> state{0};  // waiting, running, done, failed
  std::atomic<bool> stopping{false};
  LatencyWindow latency;
  bool opened = false, failed_open = false, closed = false, source_finished = false;
  std::thread thread;
  std::exception_ptr failure;
};

Harness::Impl::Impl(const std::string& type_name, const std::map<std::string, std::string>& texts,
                    HarnessOptions options)
    : type(Registry::instance().find(type_name)), name(type_name) {
  if (!type) {
    throw InputError("harness",
                     "unknown node type '" + type_name + "' (see 'mocap graph inspect')");
  }
  const SourceLocation where{"harness", 0};
  NodeSpec spec{name, type_name, {}, where};
  for (const auto& [param, text] : texts) spec.params[param] = ParamText{text, where};
  std::vector<std::string> errors;
  params = resolve_params(spec, type->contract, errors);
  if (!errors.empty()) {
    std::string message;
    for (const std::string& e : errors) message += (message.empty() ? "" : "\n") + e;
    throw InputError("", message);
  }
  const Contract& contract = type->contract;
  std::vector<std::size_t> counts;
  std::vector<EdgePolicy> policies;
  for (const PortSpec& port : contract.inputs()) {
    std::size_t count = 1;
    if (port.repeated) {
      const auto it = options.repeated.find(port.name);
      count = it == options.repeated.end() ? port.min_count : it->second;
      if (count < port.min_count || count > port.max_count) {
        throw std::invalid_argument(
            "harness: input '" + port.name + "' takes " + std::to_string(port.min_count) + " to " +
            std::to_string(port.max_count) + " edges, not " + std::to_string(count));
      }
    } else if (std::find(options.unconnected.begin(), options.unconnected.end(), port.name) !=
               options.unconnected.end()) {
      if (!port.optional) {
        throw std::invalid_argument("harness: input '" + port.name + "' is not optional");
      }
      count = 0;
    }
    const auto policy = options.policies.find(port.name);
    for (std::size_t i = 0; i < count; ++i) {
      policies.push_back(policy == options.policies.end()
                             ? EdgePolicy{PolicyKind::blocking, 1'000'000}
                             : policy->second);
    }
    counts.push_back(count);
  }
  slot_ended.assign(policies.size(), false);
  inputs =
      std::make_unique<NodeInputs>(contract, counts, std::move(policies), params, options.at_bound);
  sent.resize(contract.outputs().size());
  ended_outputs.assign(contract.outputs().size(), false);
  instance = type->create();
}

void Harness::Impl::send_packet(std::string_view port, std::size_t stream, Packet packet) {
  const int index = type->contract.output_index(port);
  if (index < 0)
    throw std::logic_error("node '" + name + "' has no output '" + std::string(port) + "'");
  const PortSpec& spec = type->contract.outputs()[static_cast<std::size_t>(index)];
  if (!spec.type.empty() && packet.type != spec.type) {
    throw std::logic_error("node '" + name + "': output '" + std::string(port) + "' carries " +
                           spec.type + ", not " + std::string(packet.type));
  }
  {
    const std::lock_guard lock(mutex);
    auto& streams = sent[static_cast<std::size_t>(index)];
    if (streams.size() <= stream) streams.resize(stream + 1);
    streams[stream].push_back(std::move(packet));
  }
  ++out;
}

NodeStats Harness::Impl::snapshot() const {
  NodeStats s;
  s.node = name;
  s.type = type->name;
  s.in = in.load();
  s.out = out.load();
  s.drops = inputs->inbox().drops() + own_drops.load();
  const auto [p50, p95] = latency.percentiles_us();
  s.p50_us = p50;
  s.p95_us = p95;
  s.queue_depth = inputs->inbox().depth();
  s.max_queue_depth = inputs->inbox().max_depth();
  static constexpr const char* kStates[] = {"waiting", "running", "done", "failed"};
  s.state = kStates[state.load()];
  const std::lock_guard lock(mutex);
  s.status = status;
  s.sync = sync_copy;
  s.drops += late_dropped(s.sync);
  return s;
}

std::size_t Harness::Impl::slot_of(std::string_view input, std::size_t index) const {
  const int i = type->contract.input_index(input);
  if (i < 0)
    throw std::logic_error("harness: " + name + " has no input '" + std::string(input) + "'");
  if (index >= inputs->count(input)) {
    throw std::logic_error("harness: input '" + std::string(input) + "' has no edge " +
                           std::to_string(index) + " (" + std::to_string(inputs->count(input)) +
                           " connected)");
  }
  return inputs->slot(static_cast<std::size_t>(i), index);
}

// --- Harness

Harness::Harness(const std::string& type, const std::map<std::string, std::string>& params,
                 HarnessOptions options)
    : impl_(std::make_unique<Impl>(type, params, std::move(options))) {}

Harness::~Harness() {
  if (impl_->thread.joinable()) {
    impl_->stopping = true;
    impl_->wake.notify_all();
    impl_->inputs->inbox().close();
    impl_->thread.join();
  }
}

bool Harness::push_packet(std::string_view input, std::size_t index, Packet packet) {
  return impl_->inputs->inbox().push(impl_->slot_of(input, index), std::move(packet));
}

void Harness::end(std::string_view input, std::size_t index) {
  const std::size_t slot = impl_->slot_of(input, index);
  if (impl_->slot_ended[slot]) return;
  impl_->slot_ended[slot] = true;
  impl_->inputs->inbox().push(slot, Packet::end_of_stream());
}

void Harness::end_all() {
  for (const PortSpec& port : impl_->type->contract.inputs()) {
    for (std::size_t i = 0; i < impl_->inputs->count(port.name); ++i) end(port.name, i);
  }
}

void Harness::open() { impl_->open_once(); }

std::size_t Harness::process_ready() {
  impl_->open_once();
  if (impl_->type->contract.is_source()) return 0;
  std::size_t calls = 0;
  while (true) {
    switch (impl_->inputs->next(false)) {
      case NodeInputs::Step::call:
        impl_->timed_process();
        ++calls;
        continue;
      case NodeInputs::Step::ended:
      case NodeInputs::Step::closed:
        impl_->close_once();
        return calls;
      case NodeInputs::Step::nothing:
        impl_->publish_sync();
        return calls;
    }
  }
}

void Harness::finish() {
  end_all();
  process_ready();
  impl_->close_once();
}

std::size_t Harness::run_source(std::size_t max_calls) {
  impl_->open_once();
  std::size_t calls = 0;
  while (calls < max_calls && !impl_->source_finished && !impl_->stopping) {
    impl_->timed_process();
    ++calls;
  }
  if (impl_->source_finished || impl_->stopping) impl_->close_once();
  return calls;
}

void Harness::start() {
  if (impl_->thread.joinable()) throw std::logic_error("harness: start() called twice");
  impl_->thread = std::thread([impl = impl_.get()] {
    try {
      impl->open_once();
      if (impl->type->contract.is_source()) {
        while (!impl->source_finished && !impl->stopping) impl->timed_process();
      } else {
        while (impl->inputs->next(true) == NodeInputs::Step::call) impl->timed_process();
      }
      impl->close_once();
    } catch (...) {
      impl->failure = std::current_exception();
      try {
        impl->close_once();
      } catch (...) {
      }
    }
  });
}

void Harness::join() {
  if (impl_->thread.joinable()) impl_->thread.join();
  if (impl_->failure) std::rethrow_exception(std::exchange(impl_->failure, nullptr));
}

void Harness::request_stop() {
  impl_->stopping = true;
  impl_->wake.notify_all();
}

void Harness::set_output_idle(std::string_view output, std::size_t index, bool idle) {
  const std::lock_guard lock(impl_->mutex);
  if (idle) {
    impl_->busy_outputs.erase({std::string(output), index});
  } else {
    impl_->busy_outputs.insert({std::string(output), index});
  }
}

std::vector<Packet> Harness::pull_packets(std::string_view output, std::size_t stream) {
  const int index = impl_->type->contract.output_index(output);
  if (index < 0) {
    throw std::logic_error("harness: " + impl_->name + " has no output '" + std::string(output) +
                           "'");
  }
  const std::lock_guard lock(impl_->mutex);
  auto& streams = impl_->sent[static_cast<std::size_t>(index)];
  if (streams.size() <= stream) return {};
  return std::exchange(streams[stream], {});
}

bool Harness::ended(std::string_view output) const {
  const int index = impl_->type->contract.output_index(output);
  const std::lock_guard lock(impl_->mutex);
  return index >= 0 && impl_->ended_outputs[static_cast<std::size_t>(index)];
}

NodeStats Harness::stats() const { return impl_->snapshot(); }

std::string Harness::status() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->status;
}

Node& Harness::node() { return *impl_->instance; }

}  // namespace mocap::graph
