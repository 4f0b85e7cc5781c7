// test.collect: records one line per message (stream, seq, frame, type, content digest, and
// optionally timing) and writes them to a file when the graph ends, so tests can compare what
// two runs received. The file is written whole and renamed into place: it is either complete or
// absent.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "graph/registry.hpp"
#include "graph/transport.hpp"

namespace mocap::nodes {
using namespace mocap::graph;

namespace {

// FNV-1a: a small, stable digest; enough to tell two payloads apart in tests.
class Digest {
 public:
  void add(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) hash_ = (hash_ ^ p[i]) * 1099511628211ULL;
  }
  template <class T>
  void add(const T& value) {
    add(&value, sizeof value);
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 14695981039346656037ULL;
};

std::uint64_t digest(const Packet& packet) {
  Digest d;
  if (packet.type == People2D::kTypeName) {
    const auto& m = static_cast<const People2D&>(*packet.message);
    d.add(m.layout);
    d.add(m.camera.data(), m.camera.size());
    for (const Person2D& p : m.people) {
      d.add(p.id);
      d.add(p.box);
      d.add(p.joints.data(), p.joints.size() * sizeof(Keypoint2D));
    }
  } else if (packet.type == People3D::kTypeName) {
    const auto& m = static_cast<const People3D&>(*packet.message);
    d.add(m.frame.kind);
    d.add(m.frame.camera.data(), m.frame.camera.size());
    for (const Person3D& p : m.people) {
      d.add(p.id);
      d.add(p.positions);
      d.add(p.rotations);
      d.add(p.root);
      d.add(p.provenance.clip.data(), p.provenance.clip.size());
    }
  } else if (packet.type == VideoFrame::kTypeName) {
    const auto& m = static_cast<const VideoFrame&>(*packet.message);
    const ImageBuffer& image = m.image;
    d.add(m.camera.data(), m.camera.size());
    d.add(image.format());
    const auto row_bytes =
        static_cast<std::size_t>(image.width() * bytes_per_pixel(image.format()));
    for (int row = 0; row < image.height(); ++row) {
      d.add(image.data() + static_cast<std::size_t>(row) * image.stride(), row_bytes);
    }
  }
  return d.value();
}

}  // namespace

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
                          static_cast<unsigned long long>(digest(packet)));
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
