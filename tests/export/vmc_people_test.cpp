// Who the VMC link sends (export/vmc_people.hpp), frame by frame, without the graph: the person
// choice rules, the port a person keeps and hands over, and the link's clock.

#include "export/vmc_people.hpp"

#include <gtest/gtest.h>

#include <initializer_list>
#include <stdexcept>

namespace mocap::exporting {
namespace {

// A person whose detected keypoints span `size` pixels.
Person3D person(int id, float size) {
  Person3D p;
  p.id = id;
  p.keypoints[0] = {0.0f, 0.0f, 1.0f};
  p.keypoints[1] = {size * 0.5f, size, 1.0f};
  return p;
}

People3D frame(std::int64_t number, std::initializer_list<Person3D> people) {
  People3D out;
  out.header.frame = number;
  out.people = people;
  return out;
}

int id_of(const Person3D* p) { return p ? p->id : -100; }

TEST(VmcPersonChoice, FirstKeepsThePersonInViewThenTakesTheEarliestSeen) {
  VmcPersonChoice choice("first");
  EXPECT_EQ(id_of(choice.choose(frame(0, {person(7, 100), person(3, 50)}))), 3);  // tie: smaller id
  EXPECT_EQ(id_of(choice.choose(frame(1, {person(9, 300), person(3, 50)}))), 3);  // kept
  EXPECT_EQ(id_of(choice.choose(frame(2, {person(9, 300), person(7, 100)}))), 7);  // seen at 0
  EXPECT_EQ(id_of(choice.choose(frame(3, {}))), -100);
}

TEST(VmcPersonChoice, LargestAndAFixedId) {
  VmcPersonChoice largest("largest"), fixed("9");
  EXPECT_EQ(id_of(largest.choose(frame(0, {person(7, 100), person(9, 300)}))), 9);
  EXPECT_EQ(id_of(largest.choose(frame(1, {person(7, 400), person(9, 300)}))), 7);
  EXPECT_EQ(id_of(fixed.choose(frame(0, {person(7, 100), person(9, 300)}))), 9);
  EXPECT_EQ(id_of(fixed.choose(frame(1, {person(7, 100)}))), -100);
}

TEST(VmcPersonChoice, AnUnknownRuleIsRefusedNamingIt) {
  for (const char* rule : {"tallest", "", "3x", "first "}) {
    try {
      VmcPersonChoice c(rule);
      ADD_FAILURE() << "accepted '" << rule << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + rule + "'"), std::string::npos);
    }
  }
}

// Two ports on loopback (real UDP sockets; nothing needs to listen to send).
TEST(VmcPorts, APersonKeepsTheirPortAndAFreedPortGoesToTheNextAfterReleaseTime) {
  VmcPorts ports("127.0.0.1", 40000, 2, 1.0);
  VmcSender* a = ports.sender_for(1, 0.0);
  VmcSender* b = ports.sender_for(2, 0.0);
  ASSERT_TRUE(a && b);
  EXPECT_NE(a, b);
  EXPECT_EQ(a->target(), ports.first_port().target());
  EXPECT_EQ(ports.sender_for(1, 0.5), a);
  EXPECT_EQ(ports.sender_for(3, 0.9), nullptr);  // both ports busy: person 2 away only 0.9 s
  EXPECT_EQ(ports.sender_for(1, 1.4), a);
  EXPECT_EQ(ports.sender_for(3, 1.3), b);  // person 2 away 1.3 s >= release 1 s
  EXPECT_EQ(ports.ports_open(), 2);
}

TEST(VmcClock, CaptureTimesWhenPresentElseFrameNumbers) {
  VmcClock by_time(30.0), by_frame(25.0);
  Header h;
  h.capture_ns = 5'000'000'000;
  h.frame = 10;
  EXPECT_DOUBLE_EQ(by_time.seconds(h), 0.0);
  h.capture_ns += 500'000'000;
  h.frame = 11;
  EXPECT_NEAR(by_time.seconds(h), 0.5, 1e-9);
  Header f;
  f.frame = 4;
  EXPECT_DOUBLE_EQ(by_frame.seconds(f), 0.0);
  f.frame = 29;
  EXPECT_DOUBLE_EQ(by_frame.seconds(f), 1.0);
}

}  // namespace
}  // namespace mocap::exporting
