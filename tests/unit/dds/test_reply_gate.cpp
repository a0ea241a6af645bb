// dds/reply_gate: a reply waits for its client's reply reader to match, at
// most the hold limit; replies to unknown clients, or to clients whose reader
// matched, pass at once.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "dh3/dds/reply_gate.hpp"

namespace dh3::dds {
namespace {

using std::chrono::seconds;

constexpr Duration kHoldLimit = seconds(60);

msg::CommandReply reply_to(const std::string& client_id, std::uint64_t seq) {
  msg::CommandReply reply;
  reply.client_id(client_id);
  reply.request_seq(seq);
  return reply;
}

std::vector<std::uint64_t> seqs(const std::vector<msg::CommandReply>& replies) {
  std::vector<std::uint64_t> out;
  for (const auto& reply : replies) out.push_back(reply.request_seq());
  return out;
}

class ReplyGateTest : public ::testing::Test {
 protected:
  GateOutcome admit(const std::string& client_id, std::uint64_t seq) {
    auto reply = reply_to(client_id, seq);
    return gate_.admit(reply);
  }

  FakeClock clock_;
  ReplyGate gate_{clock_, kHoldLimit};
};

TEST_F(ReplyGateTest, AReplyToAClientIdOfNoKnownParticipantPasses) {
  // Another vendor's client may put any id in its requests.
  EXPECT_EQ(admit("cyclone-client", 1), GateOutcome::pass);
  EXPECT_EQ(gate_.held(), 0u);
  EXPECT_FALSE(gate_.next_expiry());
}

TEST_F(ReplyGateTest, AReplyWaitsForItsClientsReaderAndGoesOutWhenItMatches) {
  gate_.participant_joined("aa");
  EXPECT_EQ(admit("aa", 1), GateOutcome::held);
  EXPECT_EQ(admit("aa", 2), GateOutcome::held);
  EXPECT_EQ(gate_.held(), 2u);
  // Another client's reader does not release them.
  gate_.participant_joined("bb");
  EXPECT_TRUE(gate_.reader_matched("bb", true).empty());
  EXPECT_THAT(seqs(gate_.reader_matched("aa", true)), ::testing::ElementsAre(1u, 2u));
  EXPECT_EQ(gate_.held(), 0u);
  // From now on its replies pass.
  EXPECT_EQ(admit("aa", 3), GateOutcome::pass);
}

TEST_F(ReplyGateTest, AReaderThatMatchedBeforeItsParticipantWasReportedCounts) {
  EXPECT_TRUE(gate_.reader_matched("aa", true).empty());
  gate_.participant_joined("aa");
  EXPECT_EQ(admit("aa", 1), GateOutcome::pass);
}

TEST_F(ReplyGateTest, RepliesAreHeldAgainOnlyWhenTheLastReaderOfAClientIsGone) {
  gate_.participant_joined("aa");
  gate_.reader_matched("aa", true);
  gate_.reader_matched("aa", true);
  gate_.reader_matched("aa", false);
  EXPECT_EQ(admit("aa", 1), GateOutcome::pass);
  gate_.reader_matched("aa", false);
  EXPECT_EQ(admit("aa", 2), GateOutcome::held);
}

TEST_F(ReplyGateTest, AHeldReplyGoesOutAfterTheHoldLimitOldestFirst) {
  gate_.participant_joined("aa");
  gate_.participant_joined("bb");
  EXPECT_EQ(admit("bb", 7), GateOutcome::held);
  clock_.advance(seconds(1));
  EXPECT_EQ(admit("aa", 1), GateOutcome::held);
  EXPECT_EQ(gate_.next_expiry(), clock_.now() - seconds(1) + kHoldLimit);
  clock_.advance(kHoldLimit - seconds(1));
  EXPECT_THAT(seqs(gate_.expire()), ::testing::ElementsAre(7u));  // aa's is 1 s younger
  clock_.advance(seconds(1));
  EXPECT_THAT(seqs(gate_.expire()), ::testing::ElementsAre(1u));
  EXPECT_FALSE(gate_.next_expiry());
}

TEST_F(ReplyGateTest, AClientThatLeavesTakesItsHeldRepliesWithIt) {
  gate_.participant_joined("aa");
  admit("aa", 1);
  admit("aa", 2);
  EXPECT_EQ(gate_.participant_left("aa"), 2u);
  EXPECT_EQ(gate_.held(), 0u);
  // Gone, it is unknown: a late reply passes (the writer's history has it).
  EXPECT_EQ(admit("aa", 3), GateOutcome::pass);
}

TEST_F(ReplyGateTest, StoppingTakesEveryHeldReply) {
  gate_.participant_joined("aa");
  gate_.participant_joined("bb");
  admit("aa", 1);
  clock_.advance(seconds(1));
  admit("bb", 2);
  EXPECT_THAT(seqs(gate_.take_all()), ::testing::ElementsAre(1u, 2u));
  EXPECT_EQ(gate_.held(), 0u);
}

}  // namespace
}  // namespace dh3::dds
