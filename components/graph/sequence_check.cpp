#include "graph/sequence_check.hpp"

namespace mocap::graph {

std::optional<SequenceEvent> SequenceCheck::check(const Header& header) {
  auto it = expected_.find(header.stream);
  const bool first = it == expected_.end();
  if (first) {
    if (expected_.size() >= kMaxStreams) expected_.clear();
    it = expected_.emplace(header.stream, 0).first;
  }
  const std::uint64_t expected = it->second;
  it->second = header.seq + 1;
  if (header.seq == expected) return std::nullopt;
  SequenceEvent event;
  event.stream = header.stream;
  event.expected = expected;
  event.got = header.seq;
  if (first) {
    event.kind = SequenceEvent::Kind::joined;
    ++joins_;
  } else if (header.seq > expected) {
    event.kind = SequenceEvent::Kind::missed;
    missed_ += header.seq - expected;
    ++gaps_;
  } else {
    event.kind = SequenceEvent::Kind::restarted;
    ++restarts_;
  }
  return event;
}

std::optional<SequenceEvent> SequenceCheck::check_end(const Header& header) {
  const auto it = expected_.find(header.stream);
  if (header.stream.empty() || it == expected_.end() || header.seq <= it->second) {
    return std::nullopt;
  }
  SequenceEvent event;
  event.stream = header.stream;
  event.expected = it->second;
  event.got = header.seq;
  missed_ += header.seq - it->second;
  ++gaps_;
  it->second = header.seq;
  return event;
}

std::string describe(const SequenceEvent& event, const std::string& edge,
                     const SequenceCheck& totals) {
  std::string text = "edge " + edge + ": stream '" + event.stream + "': ";
  if (event.kind == SequenceEvent::Kind::missed) {
    text += std::to_string(event.missed()) + " messages missed (seq " +
            std::to_string(event.expected) + " to " + std::to_string(event.got - 1) + ")";
  } else if (event.kind == SequenceEvent::Kind::joined) {
    text += "first message is seq " + std::to_string(event.got) + ": joined mid-stream (" +
            std::to_string(event.got) + " earlier messages not received here)";
  } else {
    text += "started again at seq " + std::to_string(event.got) + " after " +
            std::to_string(event.expected - 1) + " (the producer restarted)";
  }
  return text + "; " + std::to_string(totals.missed()) + " missed in " +
         std::to_string(totals.gaps()) + " gaps, " + std::to_string(totals.restarts()) +
         " restarts, " + std::to_string(totals.joins()) + " joined mid-stream so far";
}

}  // namespace mocap::graph
