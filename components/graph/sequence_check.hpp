#pragma once
// Sequence numbers on an edge that arrives from another process: every stream counts its
// messages from 0 (Header::seq), so a jump forward means messages never arrived (a producer or
// middle process killed and restarted, a peer that lost its connection, or drops upstream of
// the edge) and a step back means the producer started its stream again. The runtime reports both
// with the edge's name instead of going on silently.

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "core/messages.hpp"

namespace mocap::graph {

struct SequenceEvent {
  enum class Kind {
    missed,     // messages expected..got-1 never arrived
    restarted,  // seq went back to `got` after `expected - 1`: the producer started again
    joined,     // the first message of a stream is seq `got` > 0: this consumer (restarted?)
                // joined it mid-stream; what came before went elsewhere or nowhere
  };
  Kind kind = Kind::missed;
  std::string stream;
  std::uint64_t expected = 0;  // the sequence number that was due
  std::uint64_t got = 0;       // the one that came
  std::uint64_t missed() const { return kind == Kind::missed ? got - expected : 0; }
};

class SequenceCheck {
 public:
  // Streams remembered per edge; beyond this many, the oldest knowledge is forgotten (an edge
  // that carries ever new stream ids must not grow without bound).
  static constexpr std::size_t kMaxStreams = 256;

  // Checks the next message's header; an event when it does not follow the previous one of its
  // stream. The first message of a stream should be seq 0 (else: joined).
  std::optional<SequenceEvent> check(const Header& header);
  // Checks an end of stream whose header names the stream and, as seq, how many messages its
  // producer sent: messages missing at the end (nothing after them to show a gap) are `missed`.
  // Nothing for an end of stream without a stream id or of a stream never seen here.
  std::optional<SequenceEvent> check_end(const Header& header);

  std::uint64_t missed() const { return missed_; }      // messages, over every gap
  std::uint64_t gaps() const { return gaps_; }          // jumps forward
  std::uint64_t restarts() const { return restarts_; }  // steps back
  std::uint64_t joins() const { return joins_; }        // streams first seen mid-stream

 private:
  std::map<std::string, std::uint64_t> expected_;
  std::uint64_t missed_ = 0, gaps_ = 0, restarts_ = 0, joins_ = 0;
};

// "edge src.out -> det.in (tcp://...): stream 'cam': 12 messages missed (seq 40 to 51); 3 gaps,
// 20 messages missed so far" and the like.
std::string describe(const SequenceEvent& event, const std::string& edge,
                     const SequenceCheck& totals);

}  // namespace mocap::graph
