#pragma once
// A small, stable digest of a packet's content (FNV-1a over its people, camera, image rows), so
// that tests can tell whether two runs delivered the same messages (test.collect writes it).
// Types it does not know digest to the same value: only the header tells them apart.

#include <cstdint>

#include "graph/packet.hpp"

namespace mocap::graph {

std::uint64_t content_digest(const Packet& packet);

}  // namespace mocap::graph
