#include "graph/runtime.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <iostream>
#include <mutex>
#include <set>
#include <thread>

#include <pthread.h>

#include "graph/inbox.hpp"
#include "graph/keys.hpp"
#include "graph/node_inputs.hpp"
#include "graph/sequence_check.hpp"
#include "graph/transport.hpp"

namespace mocap::graph {

using Clock = std::chrono::steady_clock;
constexpr auto kRepeatEndOfStream = std::chrono::milliseconds(500);
constexpr auto kAcknowledgementTimeout = std::chrono::milliseconds(30000);

class NodeRunner;

// One ZeroMQ edge arriving in this process: a thread that receives, decodes, checks the sequence
// numbers and queues.
struct IncomingEdge {
  std::string name;
  std::unique_ptr<Receiver> receiver;
  NodeRunner* consumer = nullptr;
  Inbox* inbox = nullptr;
  std::size_t port = 0;
  SequenceCheck sequence;
  std::thread thread;
};

struct Runtime::Impl {
  Impl(const ResolvedGraph& g, RunOptions o) : graph(g), options(std::move(o)) {}
  ~Impl();

  void log(const std::string& message) const {
    if (options.log) {
      options.log(message);
    } else {
      std::cerr << message << "\n";
    }
  }
  void request_stop() {
    {
      std::lock_guard lock(mutex);
      if (stopping) return;
      stopping = true;
      stop_time = Clock::now();
    }
    wake.notify_all();
  }
  void fail(const std::string& message) {
    {
      std::lock_guard lock(mutex);
      if (error.empty()) error = message;
      if (!stopping) stopped_by_failure = true;
    }
    request_stop();
  }
  bool stop_requested() const {
    std::lock_guard lock(mutex);
    return stopping;
  }
  // True once a stop was requested longer than the drain timeout ago: waits give up then.
  bool drain_expired() const {
    std::lock_guard lock(mutex);
    return stopping && Clock::now() - stop_time > options.drain_timeout;
  }
  // A stop asked for (a signal) whose drain deadline has passed: queued messages are left then.
  // A node's failure drains everything already queued (what came before the failure is kept).
  bool abandon_queued() const {
    std::lock_guard lock(mutex);
    return stopping && !stopped_by_failure && Clock::now() - stop_time > options.drain_timeout;
  }
  bool auxiliary_released() const {
    std::lock_guard lock(mutex);
    return aux_released;
  }
  void node_finished(bool blocks_auxiliary) {
    if (!blocks_auxiliary) return;
    {
      std::lock_guard lock(mutex);
      if (--aux_blockers == 0) aux_released = true;
    }
    wake.notify_all();
  }
  // Sleeps up to `duration`; false when the caller should stop.
  bool sleep_for(std::chrono::nanoseconds duration, bool auxiliary) {
    std::unique_lock lock(mutex);
    const auto must_stop = [&] { return stopping || (auxiliary && aux_released); };
    return !wake.wait_for(lock, duration, must_stop);
  }

  void build();
  bool uses_transport(const EdgeSpec& edge) const;
  SocketOptions socket_options(const EdgeSpec& edge, bool binds) const;
  void add_receiving_half(const EdgeSpec& edge);
  void add_sending_half(const EdgeSpec& edge);
  NodeRunner* runner(std::string_view name) const;
  void receive_loop(IncomingEdge& edge);
  void check_sequence(IncomingEdge& edge, const Header& header, bool end);
  GraphStats snapshot() const;
  void join_nodes();
  void wait_for_acknowledgements();

  ResolvedGraph graph;
  RunOptions options;
  TransportContext transport;  // first member to be built, last to go: sockets close before it
  std::vector<std::unique_ptr<NodeRunner>> runners;
  std::vector<std::unique_ptr<IncomingEdge>> incoming;
  std::atomic<bool> receivers_done{false};

  mutable std::mutex mutex;
  std::condition_variable wake;
  bool stopping = false;
  bool stopped_by_failure = false;  // the stop came from a failing node, not a request
  Clock::time_point stop_time;
  int aux_blockers = 0;
  bool aux_released = false;
  std::string error;
};

// A node instance, its thread and its view of the graph (the Context it sees).
class NodeRunner final : public Context {
 public:
  struct RemoteOutput {
    std::unique_ptr<Sender> sender;
    bool lossy = false;
  };
  struct Output {
    std::string type;  // resolved message type, empty when any
    std::vector<std::pair<Inbox*, std::size_t>> local;
    std::vector<RemoteOutput> remote;
    Header last_sent;  // of the last message, for the end of stream on ZeroMQ edges
    bool sent_any = false;
  };

  NodeRunner(Runtime::Impl& runtime, const ResolvedNode& node, std::vector<EdgePolicy> policies,
             AtBound at_bound)
      : runtime_(runtime),
        node_(node),
        contract_(node.type->contract),
        inputs_(node.type->contract, node.input_counts, std::move(policies), node.params, at_bound),
        inbox_(inputs_.inbox()) {
    // One Output per stream: a plain output has one, a repeated one one per edge of its input.
    const auto& ports = contract_.outputs();
    for (std::size_t i = 0; i < ports.size(); ++i) {
      first_output_.push_back(outputs_.size());
      const std::size_t streams = ports[i].repeated
                                      ? node.input_counts[static_cast<std::size_t>(
                                            contract_.input_index(ports[i].per_edge_of))]
                                      : 1;
      for (std::size_t k = 0; k < streams; ++k) outputs_.emplace_back().type = node.output_types[i];
    }
    first_output_.push_back(outputs_.size());
    instance_ = node.type->create();
  }

  Inbox& inbox() { return inbox_; }
  // Stream `index` of output port `port` (contract order), or null when it has no such stream.
  Output* output(std::size_t port, std::size_t index) {
    const std::size_t slot = first_output_[port] + index;
    return slot < first_output_[port + 1] ? &outputs_[slot] : nullptr;
  }
  const ResolvedNode& resolved() const { return node_; }
  void set_blocks_auxiliary(bool blocks) { blocks_auxiliary_ = blocks; }

  void start() {
    thread_ = std::thread([this] { run(); });
  }
  void join() {
    if (thread_.joinable()) thread_.join();
  }
  bool finished() const { return thread_finished_; }

  // After the node ended (and its thread was joined): repeats the end of stream on every ZeroMQ
  // output, without waiting, for a consumer that restarted after the first one. Returns true when
  // every consumer has acknowledged an end of stream at least once.
  bool repeat_end_of_stream(bool resend) {
    bool all_acknowledged = true;
    for (Output& out : outputs_) {
      for (RemoteOutput& remote : out.remote) {
        if (resend) remote.sender->send(end_of_stream(out), [] { return true; });
        all_acknowledged = remote.sender->poll_acknowledgement() && all_acknowledged;
      }
    }
    return all_acknowledged;
  }

  NodeStats snapshot() const {
    NodeStats s;
    s.node = node_.name;
    s.type = node_.type->name;
    s.process = node_.process;
    s.in = in_.load();
    s.out = out_.load();
    s.drops = inbox_.drops() + own_drops_.load();
    const auto [p50, p95] = latency_.percentiles_us();
    s.p50_us = p50;
    s.p95_us = p95;
    s.queue_depth = inbox_.depth();
    s.max_queue_depth = inbox_.max_depth();
    const auto [wait50, wait95] = inbox_.wait_percentiles_us();
    s.wait_p50_us = wait50;
    s.wait_p95_us = wait95;
    s.blocked_s = static_cast<double>(blocked_ns_.load()) * 1e-9;
    {
      const std::lock_guard lock(status_mutex_);  // the synchroniser's counters change as it runs
      s.sync = sync_stats_;
    }
    s.drops += late_dropped(s.sync);
    static constexpr const char* kStates[] = {"waiting", "running", "done", "failed"};
    s.state = kStates[state_.load()];
    {
      const std::lock_guard lock(status_mutex_);
      s.status = status_;
    }
    return s;
  }

  // --- Context
  const std::string& node_name() const override { return node_.name; }
  std::string_view input_port() const override { return inputs_.port_name(); }
  const Packet* find_input(std::string_view port, std::size_t index) const override {
    return inputs_.find(port, index);
  }
  std::size_t input_count(std::string_view port) const override { return inputs_.count(port); }
  bool in_set() const override { return inputs_.in_set(); }
  const Header* input_header() const override { return inputs_.header(); }
  using Context::send_packet;
  void send_packet(std::string_view port, std::size_t index, Packet packet) override;
  bool output_idle(std::string_view port, std::size_t index) const override;
  void count_drop() override { ++own_drops_; }
  void report_status(std::string text) override {
    const std::lock_guard lock(status_mutex_);  // snapshots are taken on other threads
    status_ = std::move(text);
  }
  void finish() override { finished_ = true; }
  bool stop_requested() const override {
    return runtime_.stop_requested() || (contract_.auxiliary() && runtime_.auxiliary_released());
  }
  bool sleep_for(std::chrono::nanoseconds duration) override {
    const auto start = Clock::now();
    const bool keep_going = runtime_.sleep_for(duration, contract_.auxiliary());
    slept_ += Clock::now() - start;
    return keep_going;
  }
  GraphStats stats() const override { return runtime_.snapshot(); }
  const ParamValue& param_value(std::string_view name) const override {
    const auto it = node_.params.find(std::string(name));
    if (it == node_.params.end()) {
      throw std::logic_error("node '" + node_.name + "': parameter '" + std::string(name) +
                             "' is not in the contract of " + node_.type->name);
    }
    return it->second;
  }

 private:
  enum State { waiting, running, done, failed };

  void run();
  void run_source();
  void run_consumer();
  void publish_sync_stats(bool now);
  void timed_process();
  void end_outputs();
  // The end of stream this node sends: its header names the stream and, as seq, how many
  // messages of it were sent (the last seq + 1), so that a consumer in another process can tell
  // that messages are missing at the end (a killed peer). A node that sent nothing passes on the
  // header of the end of stream it received.
  Packet end_of_stream(const Output& out) const {
    if (!out.sent_any) return Packet::end_of_stream(inputs_.received_end());
    Header header = out.last_sent;
    ++header.seq;
    return Packet::end_of_stream(std::move(header));
  }
  void record_failure(const char* stage, const std::string& what) {
    runtime_.fail("node '" + node_.name + "' (" + node_.type->name + ") failed in " + stage + ": " +
                  what);
    failed_ = true;
    inbox_.close();  // upstream must not wait for a node that no longer reads
  }

  Runtime::Impl& runtime_;
  const ResolvedNode& node_;
  const Contract& contract_;
  std::unique_ptr<Node> instance_;
  NodeInputs inputs_;
  Inbox& inbox_;
  std::vector<Output> outputs_;
  std::vector<std::size_t> first_output_;  // per output port: its first stream; then the total
  bool blocks_auxiliary_ = false;
  std::thread thread_;

  bool finished_ = false, failed_ = false;
  Clock::duration slept_{};
  SyncStats sync_stats_;  // under status_mutex_
  Clock::time_point sync_published_{};

  std::atomic<std::uint64_t> in_{0}, out_{0}, own_drops_{0};
  std::atomic<std::int64_t> blocked_ns_{0};  // waiting for room downstream (send_packet)
  std::uint64_t abandoned_at_stop_ = 0;      // data left in the inbox after the drain deadline
  std::atomic<int> state_{waiting};
  std::atomic<bool> thread_finished_{false};
  LatencyWindow latency_;
  mutable std::mutex status_mutex_;
  std::string status_;
};

void NodeRunner::send_packet(std::string_view port, std::size_t stream, Packet packet) {
  const int index = contract_.output_index(port);
  Output* found = index < 0 ? nullptr : output(static_cast<std::size_t>(index), stream);
  if (!found) {
    throw std::logic_error("node '" + node_.name + "' has no output '" +
                           indexed_port(port, static_cast<long>(stream)) + "'");
  }
  Output& out = *found;
  if (!out.type.empty() && packet.type != out.type) {
    throw std::logic_error("node '" + node_.name + "': output '" + std::string(port) +
                           "' carries " + out.type + ", not " + std::string(packet.type));
  }
  // Waiting for room in a full downstream queue is back-pressure, not this node's work: it is
  // left out of the processing time, as sleeping is.
  const auto push_start = Clock::now();
  for (auto& [inbox, input] : out.local) inbox->push(input, packet);
  const auto pushing = Clock::now() - push_start;
  slept_ += pushing;
  blocked_ns_ += std::chrono::duration_cast<std::chrono::nanoseconds>(pushing).count();
  for (RemoteOutput& remote : out.remote) {
    const auto give_up = [&] { return remote.lossy || runtime_.drain_expired(); };
    if (!remote.sender->send(packet, give_up)) ++own_drops_;
  }
  if (!out.remote.empty()) {
    out.last_sent = packet.header();
    out.sent_any = true;
  }
  ++out_;
}

bool NodeRunner::output_idle(std::string_view port, std::size_t stream) const {
  const int index = contract_.output_index(port);
  const std::size_t slot =
      index < 0 ? outputs_.size() : first_output_[static_cast<std::size_t>(index)] + stream;
  if (index < 0 || slot >= first_output_[static_cast<std::size_t>(index) + 1]) {
    throw std::logic_error("node '" + node_.name + "' has no output '" +
                           indexed_port(port, static_cast<long>(stream)) + "'");
  }
  const Output& out = outputs_[slot];
  return std::all_of(out.local.begin(), out.local.end(),
                     [](const auto& consumer) { return consumer.first->idle(); });
}

void NodeRunner::timed_process() {
  slept_ = {};
  const auto start = Clock::now();
  instance_->process(*this);
  const auto busy = Clock::now() - start - slept_;
  latency_.add(std::chrono::duration_cast<std::chrono::nanoseconds>(busy).count());
}

void NodeRunner::run_source() {
  while (!finished_ && !stop_requested()) timed_process();
}

void NodeRunner::run_consumer() {
  while (inputs_.next(true) == NodeInputs::Step::call) {
    in_ = inputs_.received();
    // A stop bounds the drain: once its deadline has passed, what is still queued is counted
    // (a drop, and a log line at the end) instead of processed, so the graph exits in time.
    if (runtime_.abandon_queued()) {
      for (const Packet& packet : inputs_.current()) {
        if (!packet.message) continue;
        ++abandoned_at_stop_;
        ++own_drops_;
      }
      continue;
    }
    timed_process();
    publish_sync_stats(false);
  }
  in_ = inputs_.received();
  publish_sync_stats(true);
}

// The synchroniser's counters for snapshots taken on other threads: copied at most every 100 ms
// while the node runs (not per message), and once at the end.
void NodeRunner::publish_sync_stats(bool now) {
  const Synchronizer* sync = inputs_.synchronizer();
  if (!sync) return;
  const auto time = Clock::now();
  if (!now && time - sync_published_ < std::chrono::milliseconds(100)) return;
  sync_published_ = time;
  const std::vector<NodeInputs::SlotName> slots = inputs_.joined_slots();
  const std::lock_guard lock(status_mutex_);
  sync_stats_ = sync->stats();
  for (std::size_t i = 0; i < slots.size(); ++i) {
    sync_stats_.inputs[i].name =
        indexed_port(slots[i].port, slots[i].repeated ? static_cast<long>(slots[i].index) : -1);
  }
}

void NodeRunner::run() {
  // The node's name on its thread (15 characters at most), so that `top -H` and /proc show
  // which node uses the cores.
  pthread_setname_np(pthread_self(), node_.name.substr(0, 15).c_str());
  state_ = running;
  bool opened = false;
  try {
    instance_->open(*this);
    opened = true;
    if (contract_.is_source()) {
      run_source();
    } else {
      run_consumer();
    }
  } catch (const std::exception& e) {
    record_failure(opened ? "process" : "open", e.what());
  }
  inputs_.clear();
  inbox_.close();
  if (abandoned_at_stop_ > 0) {
    runtime_.log("node '" + node_.name + "': " + std::to_string(abandoned_at_stop_) +
                 " queued message(s) not processed: the stop's drain deadline (" +
                 std::to_string(runtime_.options.drain_timeout.count()) + " ms) passed");
  }
  if (opened) {
    try {
      instance_->close(*this);
    } catch (const std::exception& e) {
      record_failure("close", e.what());
    }
  }
  end_outputs();
  state_ = failed_ ? failed : done;
  runtime_.node_finished(blocks_auxiliary_);
  thread_finished_ = true;
}

void NodeRunner::end_outputs() {
  for (Output& out : outputs_) {
    const Packet eos = end_of_stream(out);
    for (auto& [inbox, input] : out.local) inbox->push(input, eos);
    for (RemoteOutput& remote : out.remote) {
      if (!remote.sender->send(eos, [&] { return runtime_.drain_expired(); })) {
        runtime_.log("node '" + node_.name + "': end of stream to " + remote.sender->endpoint() +
                     " not delivered");
      }
    }
  }
}

// --- building the runtime

namespace {

// The inbox slot of an edge's end: a node's inputs in contract order, a repeated one taking one
// slot per edge (NodeInputs).
std::size_t input_slot(const ResolvedNode& node, const PortRef& to) {
  const auto input = static_cast<std::size_t>(node.type->contract.input_index(to.port));
  std::size_t slot = 0;
  for (std::size_t i = 0; i < input; ++i) slot += node.input_counts[i];
  return slot + static_cast<std::size_t>(std::max(to.index, 0));
}

// True when two of the node's joined edges have a node upstream in common (the 2D people and,
// behind a slower chain, their 3D): a synchroniser that waited with one input full would make
// that common node wait, which may starve the other input for good. Such joins pass the oldest
// set on partial at the bound instead (graph/synchronizer.hpp). Independent sources wait.
bool joins_branches_of_one_source(const ResolvedGraph& graph, const ResolvedNode& node) {
  const Contract& contract = node.type->contract;
  if (!contract.joined()) return false;
  const auto upstream_of = [&](const std::string& start) {
    std::set<std::string> seen{start};
    std::vector<std::string> todo{start};
    while (!todo.empty()) {
      const std::string current = todo.back();
      todo.pop_back();
      for (const EdgeSpec& edge : graph.spec.edges) {
        if (edge.to.node == current && seen.insert(edge.from.node).second) {
          todo.push_back(edge.from.node);
        }
      }
    }
    return seen;
  };
  std::set<std::string> seen;
  for (const EdgeSpec& edge : graph.spec.edges) {
    if (edge.to.node != node.name || !contract.is_joined(edge.to.port)) continue;
    for (const std::string& upstream : upstream_of(edge.from.node)) {
      if (!seen.insert(upstream).second) return true;
    }
  }
  return false;
}

}  // namespace

NodeRunner* Runtime::Impl::runner(std::string_view name) const {
  for (const auto& r : runners) {
    if (r->resolved().name == name) return r.get();
  }
  return nullptr;
}

bool Runtime::Impl::uses_transport(const EdgeSpec& edge) const {
  return !edge.transport.empty() && !options.single_process;
}

SocketOptions Runtime::Impl::socket_options(const EdgeSpec& edge, bool binds) const {
  SocketOptions socket;
  // Lossy edges drain the socket at once and decide what to drop in the inbox, where it is
  // counted; blocking edges let ZeroMQ queue only as much as the edge allows.
  socket.high_water_mark = static_cast<int>(edge.policy.lossy() ? 1000 : edge.policy.capacity);
  // CURVE (docs/security.md): the consumer binds and is the server.
  if (edge.curve.enabled()) {
    socket.curve = load_curve_keys(edge.curve.server, edge.curve.clients, binds);
  }
  return socket;
}

void Runtime::Impl::add_receiving_half(const EdgeSpec& edge) {
  NodeRunner* to = runner(edge.to.node);
  if (!to || !uses_transport(edge)) return;
  // The consumer binds: it is the stable end that a restarted producer reconnects to.
  auto incoming_edge = std::make_unique<IncomingEdge>();
  incoming_edge->name = edge.str() + " (" + edge.transport + ")";
  incoming_edge->receiver =
      std::make_unique<Receiver>(transport, edge.transport, socket_options(edge, true));
  incoming_edge->consumer = to;
  incoming_edge->inbox = &to->inbox();
  incoming_edge->port = input_slot(to->resolved(), edge.to);
  incoming.push_back(std::move(incoming_edge));
}

void Runtime::Impl::add_sending_half(const EdgeSpec& edge) {
  NodeRunner* from = runner(edge.from.node);
  NodeRunner* to = runner(edge.to.node);
  if (!from) return;
  NodeRunner::Output& out = *from->output(
      static_cast<std::size_t>(from->resolved().type->contract.output_index(edge.from.port)),
      static_cast<std::size_t>(std::max(edge.from.index, 0)));  // checked by validation
  if (uses_transport(edge)) {
    out.remote.push_back({std::make_unique<Sender>(transport, edge.transport, Sender::Pattern::edge,
                                                   socket_options(edge, false)),
                          edge.policy.lossy()});
    return;
  }
  if (!to) {
    throw std::runtime_error(edge.where.str() + ": edge " + edge.str() +
                             " crosses processes without a transport");
  }
  out.local.emplace_back(&to->inbox(), input_slot(to->resolved(), edge.to));
}

void Runtime::Impl::build() {
  if (!options.process.empty()) {
    const bool known = std::any_of(graph.spec.processes.begin(), graph.spec.processes.end(),
                                   [&](const ProcessSpec& p) { return p.name == options.process; });
    if (!known) throw std::runtime_error("the graph has no process '" + options.process + "'");
  }
  for (const ResolvedNode& node : graph.nodes) {
    if (!options.process.empty() && node.process != options.process) continue;
    std::size_t slots = 0;
    for (std::size_t count : node.input_counts) slots += count;
    std::vector<EdgePolicy> policies(slots);
    for (const EdgeSpec& edge : graph.spec.edges) {
      if (edge.to.node == node.name) policies[input_slot(node, edge.to)] = edge.policy;
    }
    const AtBound at_bound =
        joins_branches_of_one_source(graph, node) ? AtBound::pass_partial : AtBound::wait;
    runners.push_back(std::make_unique<NodeRunner>(*this, node, std::move(policies), at_bound));
  }
  // Every receiving end binds before any sender connects (inproc:// wants the binder first).
  for (const EdgeSpec& edge : graph.spec.edges) add_receiving_half(edge);
  for (const EdgeSpec& edge : graph.spec.edges) add_sending_half(edge);
  // Auxiliary sources (statistics reporters) run until every node that does not depend on them
  // has finished; with no such node, until the graph is stopped.
  std::set<std::string> downstream_of_aux;
  for (const ResolvedNode& node : graph.nodes) {  // topological order: one pass suffices
    if (node.type->contract.auxiliary()) downstream_of_aux.insert(node.name);
    for (const EdgeSpec& edge : graph.spec.edges) {
      if (edge.to.node == node.name && downstream_of_aux.count(edge.from.node)) {
        downstream_of_aux.insert(node.name);
      }
    }
  }
  for (const auto& r : runners) {
    const bool blocks = !downstream_of_aux.count(r->resolved().name);
    r->set_blocks_auxiliary(blocks);
    aux_blockers += blocks ? 1 : 0;
  }
}

void Runtime::Impl::receive_loop(IncomingEdge& edge) {
  std::uint64_t rejected = 0;
  while (true) {
    if (drain_expired() || receivers_done) {
      // The producer's end of stream did not come in time: end the edge here.
      edge.inbox->push(edge.port, Packet::end_of_stream());
      return;
    }
    Receiver::Result result = edge.receiver->receive(std::chrono::milliseconds(100));
    if (!result.rejected.empty()) {
      if (++rejected <= 5 || rejected % 1000 == 0) {
        log("edge " + edge.name + ": rejected a malformed message (" + std::to_string(rejected) +
            " so far): " + result.rejected);
      }
      continue;
    }
    if (!result.message) continue;
    const bool eos = result.message->packet.is_end_of_stream();
    check_sequence(edge, result.message->packet.header(), eos);
    if (!edge.inbox->push(edge.port, std::move(result.message->packet))) return;  // consumer gone
    if (eos) {
      edge.receiver->acknowledge_end();
      return;
    }
  }
}

// Messages missed on an edge (a peer killed and restarted, a lost connection, drops upstream) or
// a stream started again are reported, never silent: a log line (the first few, then every
// 1000th) and the consumer's status line in the statistics.
void Runtime::Impl::check_sequence(IncomingEdge& edge, const Header& header, bool end) {
  const std::optional<SequenceEvent> event =
      end ? edge.sequence.check_end(header) : edge.sequence.check(header);
  if (!event) return;
  const std::string text = describe(*event, edge.name, edge.sequence);
  const std::uint64_t events =
      edge.sequence.gaps() + edge.sequence.restarts() + edge.sequence.joins();
  if (events <= 5 || events % 1000 == 0) log(text);
  edge.consumer->report_status(text);
}

// Joins node threads as they finish. Meanwhile, nodes that have ended keep repeating their end of
// stream on ZeroMQ edges: a consumer process restarted by the supervisor after the first one
// would otherwise wait for it forever.
void Runtime::Impl::join_nodes() {
  std::vector<bool> joined(runners.size(), false);
  auto last_repeat = Clock::now();
  for (std::size_t left = runners.size(); left > 0;) {
    for (std::size_t i = 0; i < runners.size(); ++i) {
      if (joined[i] || !runners[i]->finished()) continue;
      runners[i]->join();
      joined[i] = true;
      --left;
    }
    const bool repeat = Clock::now() - last_repeat > kRepeatEndOfStream;
    if (repeat) last_repeat = Clock::now();
    for (std::size_t i = 0; i < runners.size(); ++i) {
      if (joined[i]) runners[i]->repeat_end_of_stream(repeat);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// Waits (bounded) until every consumer in another process has confirmed the end of stream, so
// that closing the sockets cannot lose the last messages.
void Runtime::Impl::wait_for_acknowledgements() {
  const auto limit = stop_requested() ? options.drain_timeout : kAcknowledgementTimeout;
  const auto deadline = Clock::now() + limit;
  auto last_repeat = Clock::now();
  while (true) {
    const bool repeat = Clock::now() - last_repeat > kRepeatEndOfStream;
    if (repeat) last_repeat = Clock::now();
    bool all = true;
    for (auto& r : runners) all = r->repeat_end_of_stream(repeat) && all;
    if (all) return;
    if (Clock::now() > deadline) {
      log("warning: a consumer in another process did not confirm the end of stream within " +
          std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(limit).count()) +
          " ms; its last messages may be lost");
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

GraphStats Runtime::Impl::snapshot() const {
  GraphStats stats;
  stats.header.stream = "stats";
  stats.header.capture_ns = realtime_ns();
  stats.graph = graph.spec.name;
  for (const auto& r : runners) stats.nodes.push_back(r->snapshot());
  return stats;
}

Runtime::Impl::~Impl() {
  receivers_done = true;
  request_stop();
  for (auto& r : runners) r->join();
  for (auto& e : incoming) {
    if (e->thread.joinable()) e->thread.join();
  }
}

// --- Runtime

Runtime::Runtime(const ResolvedGraph& graph, RunOptions options)
    : impl_(std::make_unique<Impl>(graph, std::move(options))) {
  impl_->build();
}

Runtime::~Runtime() = default;

RunResult Runtime::run() {
  for (auto& edge : impl_->incoming) {
    IncomingEdge* e = edge.get();
    e->thread = std::thread([this, e] { impl_->receive_loop(*e); });
  }
  for (auto& r : impl_->runners) r->start();
  impl_->join_nodes();
  impl_->receivers_done = true;
  for (auto& e : impl_->incoming) e->thread.join();
  impl_->wait_for_acknowledgements();
  RunResult result;
  result.stats = impl_->snapshot();
  std::lock_guard lock(impl_->mutex);
  result.ok = impl_->error.empty();
  result.error = impl_->error;
  result.stopped = impl_->stopping;
  return result;
}

void Runtime::request_stop() { impl_->request_stop(); }

GraphStats Runtime::stats() const { return impl_->snapshot(); }

}  // namespace mocap::graph
