// test.collect: records one line per message (stream, seq, frame, type, content digest, and
// optionally timing) and writes them to a file when the graph ends, so tests can compare what
// two runs received. The file is written whole and renamed into place: it is either complete or
// absent.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "graph/packet_digest.hpp"
#include "graph/registry.hpp"
#include "graph/transport.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

class TestCollect : public Node {
 public:
  static void contract(Contract& c) {
    c.doc(
        "Writes one line per message (stream seq frame type digest [capture_ns latency_us]) to a "
        "file at the end");
    c.input_any("in");
    c.required_param<std::string>("path", "file to write when the graph ends");
    c.param<bool>("timing", false, "add capture time and end-to-end latency to each line");
  }
  void open(Context& ctx) override {
    path_ = ctx.param<std::string>("path");
    timing_ = ctx.param<bool>("timing");
  }
  void process(Context& ctx) override {
    const Packet& packet = ctx.current("in");
    const Header& h = packet.header();
    char line[512];
    int n = std::snprintf(line, sizeof line, "%s %llu %lld %.*s %016llx", h.stream.c_str(),
                          static_cast<unsigned long long>(h.seq), static_cast<long long>(h.frame),
                          static_cast<int>(packet.type.size()), packet.type.data(),
                          static_cast<unsigned long long>(content_digest(packet)));
    if (timing_) {
      std::snprintf(line + n, sizeof line - static_cast<std::size_t>(n), " %lld %.1f",
                    static_cast<long long>(h.capture_ns),
                    static_cast<double>(realtime_ns() - h.capture_ns) / 1000.0);
    }
    lines_.emplace_back(line);
  }
  void close(Context&) override {
    const std::string temporary = path_ + ".partial";
    {
      std::ofstream out(temporary);
      for (const std::string& line : lines_) out << line << "\n";
      if (!out.flush()) throw std::runtime_error("cannot write " + temporary);
    }
    std::filesystem::rename(temporary, path_);
  }

 private:
  std::string path_;
  bool timing_ = false;
  std::vector<std::string> lines_;
};

MOCAP_REGISTER_NODE("test.collect", TestCollect)

}  // namespace mocap::nodes
