#pragma once
// What travels along an edge inside a process: a shared immutable message and its type name.

#include <memory>
#include <string_view>

#include "core/messages.hpp"

namespace mocap::graph {

struct Packet {
  std::shared_ptr<const Message> message;
  std::string_view type;  // the message type's kTypeName (static storage)

  template <class T>
  static Packet of(std::shared_ptr<const T> m) {
    return Packet{std::move(m), T::kTypeName};
  }
  static Packet end_of_stream(Header header = {}) {
    auto eos = std::make_shared<EndOfStream>();
    eos->header = std::move(header);
    return of<EndOfStream>(std::move(eos));
  }

  bool is_end_of_stream() const { return type == EndOfStream::kTypeName; }
  const Header& header() const { return message->header; }
};

}  // namespace mocap::graph
