#pragma once
// Whether a person found one way is found again another way: some find's box overlaps theirs by
// IoU > 0.5, the detection benchmark's match. For any finds with a `box` (Detection,
// MovenetPerson).

#include <algorithm>

#include "core/messages.hpp"
#include "detect/centernet.hpp"

namespace mocap::test {

template <class Finds>
bool found_again(const Box2D& box, const Finds& finds) {
  return std::any_of(finds.begin(), finds.end(),
                     [&](const auto& find) { return detect::iou(box, find.box) > 0.5f; });
}

}  // namespace mocap::test
