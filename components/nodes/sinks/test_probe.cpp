// test.probe: the measuring end of soak and load tests. For every message it appends one line
//   seq latency_us
// to a file and flushes it (so a harness can read it while the graph runs, and memory does not
// grow with the length of the run); latency is now minus the capture time (CLOCK_REALTIME).
// It checks the sequence numbers of each stream: messages missed (gaps), repeated or out of order
// are counted, shown in the status line and printed when the graph ends.

#include <cstdio>
#include <iostream>
#include <map>
#include <memory>

#include "core/input_error.hpp"
#include "graph/registry.hpp"
#include "graph/transport.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TestProbe : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Appends 'seq latency_us' per message to a file (flushed); counts sequence gaps, "
        "repeats and reordering per stream");
    c.input_any("in");
    c.required_param<std::string>("path", "file to write, one line per message");
  }
  void open(Context& ctx) override {
    path_ = ctx.param<std::string>("path");
    file_.reset(std::fopen(path_.c_str(), "w"));
    if (!file_) throw InputError(path_, "cannot create the file");
  }
  void process(Context& ctx) override {
    const Header& h = ctx.current("in").header();
    const double latency_us = static_cast<double>(realtime_ns() - h.capture_ns) / 1000.0;
    if (std::fprintf(file_.get(), "%llu %.1f\n", static_cast<unsigned long long>(h.seq),
                     latency_us) < 0 ||
        std::fflush(file_.get()) != 0) {
      throw InputError(path_, "write failed (disk full?)");
    }
    ++messages_;
    const auto [it, first] = next_seq_.try_emplace(h.stream, h.seq + 1);
    if (first) {
      missed_ += h.seq;  // a stream seen from its middle
      gaps_ += h.seq > 0 ? 1 : 0;
    } else if (h.seq >= it->second) {
      missed_ += h.seq - it->second;
      gaps_ += h.seq > it->second ? 1 : 0;
      it->second = h.seq + 1;
    } else {
      ++out_of_order_;  // a repeat or a step back (a restarted producer)
      it->second = h.seq + 1;
    }
    if (gaps_ + out_of_order_ != reported_) {
      reported_ = gaps_ + out_of_order_;
      ctx.report_status(summary());
    }
  }
  void close(Context& ctx) override {
    file_.reset();
    std::cerr << "test.probe '" << ctx.node_name() << "': " << summary() << "\n";
  }

 private:
  std::string summary() const {
    return std::to_string(messages_) + " messages, " + std::to_string(missed_) + " missed in " +
           std::to_string(gaps_) + " gaps, " + std::to_string(out_of_order_) +
           " repeated or out of order";
  }
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::string path_;
  std::unique_ptr<std::FILE, Closer> file_;
  std::map<std::string, std::uint64_t> next_seq_;  // per stream: the sequence number expected
  std::uint64_t messages_ = 0, missed_ = 0, gaps_ = 0, out_of_order_ = 0, reported_ = 0;
};

MOCAP_REGISTER_NODE("test.probe", TestProbe)

}  // namespace mocap::nodes
