#include "graph/packet_digest.hpp"

#include <cstddef>

#include "core/messages.hpp"

namespace mocap::graph {
namespace {

class Fnv1a {
 public:
  void add(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) hash_ = (hash_ ^ p[i]) * 1099511628211ULL;
  }
  template <class T>
  void add(const T& value) {
    add(&value, sizeof value);
  }
  void add_text(const std::string& text) { add(text.data(), text.size()); }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 14695981039346656037ULL;
};

void add_people(Fnv1a& d, const People2D& m) {
  d.add(m.layout);
  d.add_text(m.camera);
  for (const Person2D& p : m.people) {
    d.add(p.id);
    d.add(p.box);
    d.add(p.joints.data(), p.joints.size() * sizeof(Keypoint2D));
  }
}

void add_people(Fnv1a& d, const People3D& m) {
  d.add(m.frame.kind);
  d.add_text(m.frame.camera);
  for (const Person3D& p : m.people) {
    d.add(p.id);
    d.add(p.positions);
    d.add(p.rotations);
    d.add(p.root);
    d.add_text(p.provenance.clip);
  }
}

void add_frame(Fnv1a& d, const VideoFrame& m) {
  const ImageBuffer& image = m.image;
  d.add_text(m.camera);
  d.add(image.format());
  const auto row_bytes = static_cast<std::size_t>(image.width() * bytes_per_pixel(image.format()));
  for (int row = 0; row < image.height(); ++row)
    d.add(image.data() + static_cast<std::size_t>(row) * image.stride(), row_bytes);
}

}  // namespace

std::uint64_t content_digest(const Packet& packet) {
  Fnv1a d;
  if (packet.type == People2D::kTypeName)
    add_people(d, static_cast<const People2D&>(*packet.message));
  else if (packet.type == People3D::kTypeName)
    add_people(d, static_cast<const People3D&>(*packet.message));
  else if (packet.type == VideoFrame::kTypeName)
    add_frame(d, static_cast<const VideoFrame&>(*packet.message));
  return d.value();
}

}  // namespace mocap::graph
