// SequenceCheck: what the runtime reports about the sequence numbers arriving on an edge from
// another process (gaps, a producer that started again, a consumer that joined mid-stream).

#include "graph/sequence_check.hpp"

#include <gtest/gtest.h>

namespace mocap::graph {
namespace {

Header header(const std::string& stream, std::uint64_t seq) { return Header{stream, seq, 0, 0}; }

TEST(SequenceCheck, ContiguousStreamsFromZeroRaiseNothing) {
  SequenceCheck check;
  for (std::uint64_t i = 0; i < 100; ++i) {
    EXPECT_FALSE(check.check(header("a", i)));
    EXPECT_FALSE(check.check(header("b", i)));  // streams are checked apart
  }
  EXPECT_EQ(check.missed(), 0u);
  EXPECT_EQ(check.gaps() + check.restarts() + check.joins(), 0u);
}

TEST(SequenceCheck, AJumpForwardIsAGapWithTheMissedRange) {
  SequenceCheck check;
  for (std::uint64_t i = 0; i <= 40; ++i) ASSERT_FALSE(check.check(header("cam", i)));
  const auto event = check.check(header("cam", 52));
  ASSERT_TRUE(event);
  EXPECT_EQ(event->kind, SequenceEvent::Kind::missed);
  EXPECT_EQ(event->expected, 41u);
  EXPECT_EQ(event->got, 52u);
  EXPECT_EQ(event->missed(), 11u);
  EXPECT_FALSE(check.check(header("cam", 53)));
  ASSERT_TRUE(check.check(header("cam", 60)));
  EXPECT_EQ(check.missed(), 17u);
  EXPECT_EQ(check.gaps(), 2u);
  const std::string text = describe(*event, "src.out -> det.in (tcp://127.0.0.1:5555)", check);
  EXPECT_NE(text.find("edge src.out -> det.in (tcp://127.0.0.1:5555): stream 'cam': 11 messages "
                      "missed (seq 41 to 51)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("17 missed in 2 gaps"), std::string::npos) << text;
}

TEST(SequenceCheck, AStepBackIsAProducerThatStartedAgain) {
  SequenceCheck check;
  for (std::uint64_t i = 0; i < 10; ++i) ASSERT_FALSE(check.check(header("s", i)));
  const auto event = check.check(header("s", 0));
  ASSERT_TRUE(event);
  EXPECT_EQ(event->kind, SequenceEvent::Kind::restarted);
  EXPECT_EQ(event->missed(), 0u);
  EXPECT_NE(describe(*event, "e", check).find("started again at seq 0 after 9"), std::string::npos);
  EXPECT_FALSE(check.check(header("s", 1)));  // and it is followed from there
  EXPECT_EQ(check.restarts(), 1u);
}

TEST(SequenceCheck, AStreamFirstSeenMidwayWasJoinedNotMissed) {
  SequenceCheck check;
  const auto event = check.check(header("s", 812));
  ASSERT_TRUE(event);
  EXPECT_EQ(event->kind, SequenceEvent::Kind::joined);
  EXPECT_EQ(check.missed(), 0u);
  EXPECT_EQ(check.joins(), 1u);
  EXPECT_NE(describe(*event, "e", check).find("first message is seq 812: joined mid-stream"),
            std::string::npos);
  EXPECT_FALSE(check.check(header("s", 813)));
}

TEST(SequenceCheck, AnEndOfStreamCountingMoreThanArrivedIsAGapAtTheEnd) {
  SequenceCheck check;
  for (std::uint64_t i = 0; i < 250; ++i) ASSERT_FALSE(check.check(header("c", i)));
  const auto event = check.check_end(header("c", 2500));  // its producer sent 2500
  ASSERT_TRUE(event);
  EXPECT_EQ(event->kind, SequenceEvent::Kind::missed);
  EXPECT_EQ(event->missed(), 2250u);
  EXPECT_NE(describe(*event, "e", check).find("2250 messages missed (seq 250 to 2499)"),
            std::string::npos);
  SequenceCheck complete;
  for (std::uint64_t i = 0; i < 10; ++i) ASSERT_FALSE(complete.check(header("c", i)));
  EXPECT_FALSE(complete.check_end(header("c", 10)));
  EXPECT_FALSE(complete.check_end(header("", 0)));        // an end of stream that says nothing
  EXPECT_FALSE(complete.check_end(header("other", 99)));  // a stream never seen here
}

TEST(SequenceCheck, EverNewStreamIdsDoNotGrowWithoutBound) {
  SequenceCheck check;
  for (std::uint64_t i = 0; i < 10 * SequenceCheck::kMaxStreams; ++i) {
    EXPECT_FALSE(check.check(header("stream-" + std::to_string(i), 0)));
  }
  EXPECT_EQ(check.joins(), 0u);
}

}  // namespace
}  // namespace mocap::graph
