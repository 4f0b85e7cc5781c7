// content_digest: equal content, equal digest; any change in people, camera or pixels changes it;
// the padding between image rows does not count.

#include "graph/packet_digest.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

namespace mocap::graph {
namespace {

Packet people(float x, const std::string& camera = "cam_01") {
  auto m = std::make_shared<People2D>();
  m->camera = camera;
  Person2D p;
  p.id = 3;
  p.joints.assign(17, Keypoint2D{10.0f, 20.0f, 0.9f});
  p.joints[5].x = x;
  m->people.push_back(p);
  return Packet::of<People2D>(m);
}

Packet frame(int stride, std::byte pixel) {
  auto bytes = std::make_shared<std::vector<std::byte>>(static_cast<std::size_t>(stride) * 2,
                                                        std::byte{0x55});
  for (int row = 0; row < 2; ++row)
    std::memset(bytes->data() + row * stride, std::to_integer<int>(pixel), 3 * 4);
  auto m = std::make_shared<VideoFrame>();
  m->image = ImageBuffer(4, 2, stride, PixelFormat::rgb8, bytes, bytes->data());
  return Packet::of<VideoFrame>(m);
}

TEST(PacketDigest, FollowsTheContentOfPeopleAndImages) {
  EXPECT_EQ(content_digest(people(1.0f)), content_digest(people(1.0f)));
  EXPECT_NE(content_digest(people(1.0f)), content_digest(people(1.5f)));
  EXPECT_NE(content_digest(people(1.0f)), content_digest(people(1.0f, "cam_02")));
  EXPECT_EQ(content_digest(frame(12, std::byte{7})), content_digest(frame(16, std::byte{7})));
  EXPECT_NE(content_digest(frame(12, std::byte{7})), content_digest(frame(12, std::byte{8})));
}

}  // namespace
}  // namespace mocap::graph
