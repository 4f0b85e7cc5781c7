#pragma once
// Runs one node alone, for tests (the idea of GStreamer's GstHarness and MediaPipe's
// CalculatorRunner): make a node of a registered type with parameters, push messages and end of
// stream into its inputs, run open / process / close in the test's thread or in the node's own,
// pull what it sent on each output, read its statistics and status line. Parameters are checked
// as a graph file's are, and inputs go through the same inbox and synchroniser as in a graph
// (graph/node_inputs.hpp), so a joined node sees the same sets.
//
//   Harness overlay("sink.overlay", {{"png_every", "1"}, {"png_dir", dir}});
//   overlay.push("people2d", people2d);           // a message (its header says its frame)
//   overlay.push("people3d", people3d);
//   overlay.finish();                             // end of stream on every input, process, close
//   EXPECT_EQ(overlay.stats().sync.complete, 1u);
//
// Lossless by default: each input queues up to a million messages, so a test may push everything
// before running in its own thread. HarnessOptions sets real edge policies (then pushes block on
// a full blocking edge while the node runs in its thread, as a producer would).

#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "graph/graph_spec.hpp"
#include "graph/node.hpp"
#include "graph/stats.hpp"
#include "graph/synchronizer.hpp"

namespace mocap::graph {

struct HarnessOptions {
  std::map<std::string, std::size_t>
      repeated;  // edges wired to each repeated input (default: its minimum)
  std::vector<std::string> unconnected;        // optional inputs left unconnected
  std::map<std::string, EdgePolicy> policies;  // per input (each of its edges); default lossless
  // How joined inputs behave at their bound: the runtime chooses pass_partial when the joined
  // edges come from one source upstream (graph/synchronizer.hpp), wait otherwise.
  AtBound at_bound = AtBound::wait;
};

class Harness {
 public:
  // Throws mocap::InputError for an unknown type or a bad parameter (the message of `mocap graph
  // validate`), std::invalid_argument for a repeated input count out of its bounds.
  explicit Harness(const std::string& type, const std::map<std::string, std::string>& params = {},
                   HarnessOptions options = {});
  ~Harness();
  Harness(const Harness&) = delete;
  Harness& operator=(const Harness&) = delete;

  // --- feeding (edge `index` of a repeated input)
  template <class T>
  void push(std::string_view input, T message, std::size_t index = 0) {
    push(input, std::make_shared<const T>(std::move(message)), index);
  }
  template <class T>
  void push(std::string_view input, std::shared_ptr<const T> message, std::size_t index = 0) {
    push_packet(input, index, Packet::of<T>(std::move(message)));
  }
  // Returns false when the node no longer reads (it failed or ended): the packet is dropped.
  bool push_packet(std::string_view input, std::size_t index, Packet packet);
  void end(std::string_view input, std::size_t index = 0);  // end of stream on that edge
  void end_all();                                           // ... on every connected edge

  // --- running in the test's thread (exceptions of the node propagate to the test)
  void open();  // done by the calls below when needed
  // Calls process() for every message or set ready now, without waiting; returns the calls.
  std::size_t process_ready();
  // end_all(), everything processed, close(), end of stream on every output.
  void finish();
  // Sources: calls process() until ctx.finish() or `max_calls`; close() after ctx.finish().
  std::size_t run_source(std::size_t max_calls);

  // --- or in the node's own thread, as the runtime runs it
  void start();  // open, then process as messages arrive; close once every input has ended
  // Waits for that thread (push the ends first); rethrows what the node threw.
  void join();
  void request_stop();  // ctx.stop_requested() becomes true, sleep_for() wakes

  // --- results
  // Everything sent so far on `output` (stream `index` of a repeated one), taken.
  std::vector<Packet> pull_packets(std::string_view output, std::size_t index = 0);
  template <class T>
  std::vector<std::shared_ptr<const T>> pull(std::string_view output, std::size_t index = 0) {
    std::vector<std::shared_ptr<const T>> messages;
    for (Packet& packet : pull_packets(output, index)) {
      if (packet.type != T::kTypeName) {
        throw std::logic_error("harness: output '" + std::string(output) + "' sent " +
                               std::string(packet.type) + ", pulled as " +
                               std::string(T::kTypeName));
      }
      messages.push_back(std::static_pointer_cast<const T>(std::move(packet.message)));
    }
    return messages;
  }
  // What ctx.output_idle() answers for that output stream (true until set): stands for the
  // consumers downstream being busy or not.
  void set_output_idle(std::string_view output, std::size_t index, bool idle);
  bool ended(std::string_view output) const;  // the node's end of stream was sent there
  NodeStats stats() const;                    // as in the graph's table (sync counts included)
  std::string status() const;                 // the last ctx.report_status() text
  Node& node();                               // the instance under test

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::graph
