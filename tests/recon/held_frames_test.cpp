// recon::HeldFrames: frames leave in input order, each once every person in it is decided, people
// decided out of step with each other; the end of the stream releases the rest.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "recon/held_frames.hpp"

namespace mocap::recon {
namespace {

using Out = std::vector<std::string>;

TEST(HeldFrames, AFrameLeavesOnceEveryPersonInItIsDecidedAndNeverBeforeAnOlderOne) {
  HeldFrames<std::string> held;
  Out out;
  auto collect = [&](std::string&& f) { out.push_back(std::move(f)); };
  EXPECT_EQ(held.hold("a", {1, 2}), 0);
  EXPECT_EQ(held.hold("b", {2}), 1);
  EXPECT_EQ(held.hold("c", {}), 2);  // nobody to wait for, but after b
  EXPECT_EQ(held.release_decided(collect), 0u);
  EXPECT_TRUE(held.decide(1, 2));  // b is decided before a
  EXPECT_EQ(held.release_decided(collect), 0u);
  EXPECT_TRUE(held.decide(0, 2));
  EXPECT_EQ(held.release_decided(collect), 0u);  // a still waits for person 1
  EXPECT_TRUE(held.decide(0, 1));
  EXPECT_EQ(held.release_decided(collect), 3u);
  EXPECT_EQ(out, (Out{"a", "b", "c"}));
  EXPECT_TRUE(held.empty());
  EXPECT_EQ(held.next_index(), 3);
}

TEST(HeldFrames, DecisionsForAbsentPeopleOrReleasedFramesAreRefused) {
  HeldFrames<int> held;
  std::vector<int> out;
  auto collect = [&](int&& f) { out.push_back(f); };
  held.hold(10, {4, 4, 7});         // a duplicate id is waited for once
  EXPECT_FALSE(held.decide(0, 5));  // not in the frame
  EXPECT_TRUE(held.decide(0, 4));
  EXPECT_FALSE(held.decide(0, 4));  // decided already
  EXPECT_FALSE(held.decide(3, 7));  // no such frame yet
  ASSERT_NE(held.find(0), nullptr);
  *held.find(0) += 1;  // a held frame can be changed in place
  EXPECT_TRUE(held.decide(0, 7));
  EXPECT_EQ(held.release_decided(collect), 1u);
  EXPECT_EQ(out, std::vector<int>{11});
  EXPECT_EQ(held.find(0), nullptr);  // gone
  EXPECT_FALSE(held.decide(0, 7));
  EXPECT_FALSE(held.decide(-1, 7));
}

TEST(HeldFrames, TheEndOfTheStreamReleasesEveryFrameInOrder) {
  HeldFrames<int> held;
  for (int i = 0; i < 5; ++i) held.hold(i, {i % 2});
  held.decide(4, 0);  // the newest decided: it must still wait for the older ones
  std::vector<int> out;
  EXPECT_EQ(held.release_decided([&](int&& f) { out.push_back(f); }), 0u);
  EXPECT_EQ(held.size(), 5u);
  EXPECT_EQ(held.release_all([&](int&& f) { out.push_back(f); }), 5u);
  EXPECT_EQ(out, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(held.hold(5, {}), 5);  // indices go on counting
}

TEST(HeldFrames, AReleaseMayHoldTheNextFrame) {
  // A node sends from the release callback and may be handed its next input meanwhile.
  HeldFrames<int> held;
  held.hold(0, {});
  std::vector<int> out;
  held.release_decided([&](int&& f) {
    out.push_back(f);
    if (f == 0) held.hold(1, {});
  });
  EXPECT_EQ(out, (std::vector<int>{0, 1}));
}

}  // namespace
}  // namespace mocap::recon
