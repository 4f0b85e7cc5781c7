#include "export/vmc_people.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mocap::exporting {

namespace {

// The extent of a person's detected keypoints (the larger of width and height, pixels); the 3D
// body's when there are fewer than two.
float size_of(const Person3D& p) {
  float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
  int n = 0;
  for (const Keypoint2D& k : p.keypoints) {
    if (!(k.confidence > 0.0f)) continue;
    x0 = std::min(x0, k.x), y0 = std::min(y0, k.y), x1 = std::max(x1, k.x), y1 = std::max(y1, k.y);
    ++n;
  }
  if (n >= 2) return std::max(x1 - x0, y1 - y0);
  float extent = 0.0f;
  for (const glm::vec3& v : p.positions) extent = std::max(extent, std::abs(v.y));
  return extent;
}

std::optional<int> whole_number(const std::string& text) {
  try {
    std::size_t used = 0;
    const int value = std::stoi(text, &used);
    if (used == text.size()) return value;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

}  // namespace

VmcPersonChoice::VmcPersonChoice(const std::string& rule) {
  if (rule == "first") return;
  if (rule == "largest") {
    largest_ = true;
    return;
  }
  fixed_id_ = whole_number(rule);
  if (!fixed_id_)
    throw std::invalid_argument("person '" + rule + "' is none of first, largest or a person id");
}

const Person3D* VmcPersonChoice::choose(const People3D& people) {
  const Person3D* best = nullptr;
  if (fixed_id_) {
    for (const Person3D& p : people.people)
      if (p.id == *fixed_id_) best = &p;
    return best;
  }
  if (largest_) {
    for (const Person3D& p : people.people)
      if (!best || size_of(p) > size_of(*best)) best = &p;
    return best;
  }
  return first(people);
}

const Person3D* VmcPersonChoice::first(const People3D& people) {
  for (const Person3D& p : people.people) {
    if (p.id < 0) continue;
    first_seen_.emplace(p.id, people.header.frame);
    if (p.id == current_) return &p;
  }
  const Person3D* best = nullptr;
  for (const Person3D& p : people.people) {
    if (p.id < 0) continue;
    if (!best || first_seen_[p.id] < first_seen_[best->id] ||
        (first_seen_[p.id] == first_seen_[best->id] && p.id < best->id))
      best = &p;
  }
  if (best) current_ = best->id;
  return best;
}

VmcPorts::VmcPorts(std::string host, int port, int max_people, double release_s)
    : host_(std::move(host)), port_(port), max_people_(max_people), release_s_(release_s) {
  sender_at(0);  // the first port is resolved now, so a bad host fails at open
}

VmcSender& VmcPorts::first_port() { return sender_at(0); }

VmcSender& VmcPorts::sender_at(int slot) {
  while (static_cast<int>(senders_.size()) <= slot)
    senders_.push_back(
        std::make_unique<VmcSender>(host_, port_ + static_cast<int>(senders_.size())));
  return *senders_[slot];
}

VmcSender* VmcPorts::sender_for(int id, double t) {
  const auto slot = slots_.find(id);
  if (slot != slots_.end()) {
    slot->second.last_seen = t;
    return &sender_at(slot->second.port);
  }
  int port = static_cast<int>(slots_.size());
  if (port >= max_people_) {
    auto oldest = slots_.end();
    for (auto it = slots_.begin(); it != slots_.end(); ++it)
      if (oldest == slots_.end() || it->second.last_seen < oldest->second.last_seen) oldest = it;
    if (oldest == slots_.end() || t - oldest->second.last_seen < release_s_) return nullptr;
    port = oldest->second.port;
    slots_.erase(oldest);
  }
  slots_.emplace(id, Slot{port, t});
  return &sender_at(port);
}

VmcPorts::Totals VmcPorts::totals() const {
  Totals t;
  for (const auto& s : senders_) {
    t.bundles += s->bundles_sent();
    t.messages += s->messages_sent();
    t.failures += s->send_failures();
  }
  return t;
}

double VmcClock::seconds(const Header& h) {
  if (!started_) {
    started_ = true;
    first_ns_ = h.capture_ns;
    first_frame_ = h.frame;
  }
  if (h.capture_ns != 0 && first_ns_ != 0)
    return static_cast<double>(h.capture_ns - first_ns_) * 1e-9;
  return static_cast<double>(h.frame - first_frame_) / fps_;
}

}  // namespace mocap::exporting
