// dds/reply_gate: a reply waits for its client's reply reader to match, at
// most the hold limit; replies to unknown clients, or to clients whose reader
// matched, pass at once; a client that never matches gets at most its cap of
// replies held, the gate at most its total. Every test runs for both gates
// the service keeps: command replies and group replies.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "reply_gate.hpp"

namespace dh3::dds {
namespace {

using std::chrono::seconds;

constexpr Duration kHoldLimit = seconds(60);
constexpr HoldCaps kCaps{.per_client = 3, .total = 5};

template <typename Reply>
Reply reply_to(const std::string& client_id, std::uint64_t seq) {
  Reply reply;
  reply.client_id(client_id);
  reply.request_seq(seq);
  return reply;
}

template <typename Reply>
std::vector<std::uint64_t> seqs(const std::vector<Reply>& replies) {
  std::vector<std::uint64_t> out;
  for (const auto& reply : replies) out.push_back(reply.request_seq());
  return out;
}

template <typename Reply>
class ReplyGateTest : public ::testing::Test {
 protected:
  GateOutcome admit(const std::string& client_id, std::uint64_t seq) {
    return admit_with(client_id, seq).outcome;
  }
  Admission admit_with(const std::string& client_id, std::uint64_t seq) {
    auto reply = reply_to<Reply>(client_id, seq);
    return gate_.admit(reply);
  }

  FakeClock clock_;
  ReplyGate<Reply> gate_{clock_, kHoldLimit, kCaps};
};

using ReplyTypes = ::testing::Types<msg::CommandReply, msg::GroupReply>;
TYPED_TEST_SUITE(ReplyGateTest, ReplyTypes);

TYPED_TEST(ReplyGateTest, AReplyToAClientIdOfNoKnownParticipantPasses) {
  // Another vendor's client may put any id in its requests.
  EXPECT_EQ(this->admit("cyclone-client", 1), GateOutcome::pass);
  EXPECT_EQ(this->gate_.held(), 0u);
  EXPECT_FALSE(this->gate_.next_expiry());
}

TYPED_TEST(ReplyGateTest, AReplyWaitsForItsClientsReaderAndGoesOutWhenItMatches) {
  this->gate_.participant_joined("aa");
  EXPECT_EQ(this->admit("aa", 1), GateOutcome::held);
  EXPECT_EQ(this->admit("aa", 2), GateOutcome::held);
  EXPECT_EQ(this->gate_.held(), 2u);
  // Another client's reader does not release them.
  this->gate_.participant_joined("bb");
  EXPECT_TRUE(this->gate_.reader_matched("bb", true).empty());
  EXPECT_THAT(seqs(this->gate_.reader_matched("aa", true)), ::testing::ElementsAre(1u, 2u));
  EXPECT_EQ(this->gate_.held(), 0u);
  // From now on its replies pass.
  EXPECT_EQ(this->admit("aa", 3), GateOutcome::pass);
}

TYPED_TEST(ReplyGateTest, AReaderThatMatchedBeforeItsParticipantWasReportedCounts) {
  EXPECT_TRUE(this->gate_.reader_matched("aa", true).empty());
  this->gate_.participant_joined("aa");
  EXPECT_EQ(this->admit("aa", 1), GateOutcome::pass);
}

TYPED_TEST(ReplyGateTest, RepliesAreHeldAgainOnlyWhenTheLastReaderOfAClientIsGone) {
  this->gate_.participant_joined("aa");
  this->gate_.reader_matched("aa", true);
  this->gate_.reader_matched("aa", true);
  this->gate_.reader_matched("aa", false);
  EXPECT_EQ(this->admit("aa", 1), GateOutcome::pass);
  this->gate_.reader_matched("aa", false);
  EXPECT_EQ(this->admit("aa", 2), GateOutcome::held);
}

TYPED_TEST(ReplyGateTest, AHeldReplyGoesOutAfterTheHoldLimitOldestFirst) {
  this->gate_.participant_joined("aa");
  this->gate_.participant_joined("bb");
  EXPECT_EQ(this->admit("bb", 7), GateOutcome::held);
  this->clock_.advance(seconds(1));
  EXPECT_EQ(this->admit("aa", 1), GateOutcome::held);
  EXPECT_EQ(this->gate_.next_expiry(), this->clock_.now() - seconds(1) + kHoldLimit);
  this->clock_.advance(kHoldLimit - seconds(1));
  EXPECT_THAT(seqs(this->gate_.expire()), ::testing::ElementsAre(7u));  // aa's is 1 s younger
  this->clock_.advance(seconds(1));
  EXPECT_THAT(seqs(this->gate_.expire()), ::testing::ElementsAre(1u));
  EXPECT_FALSE(this->gate_.next_expiry());
}

TYPED_TEST(ReplyGateTest, AClientThatLeavesTakesItsHeldRepliesWithIt) {
  this->gate_.participant_joined("aa");
  this->admit("aa", 1);
  this->admit("aa", 2);
  EXPECT_EQ(this->gate_.participant_left("aa"), 2u);
  EXPECT_EQ(this->gate_.held(), 0u);
  // Gone, it is unknown: a late reply passes (the writer's history has it).
  EXPECT_EQ(this->admit("aa", 3), GateOutcome::pass);
}

TYPED_TEST(ReplyGateTest, StoppingTakesEveryHeldReply) {
  this->gate_.participant_joined("aa");
  this->gate_.participant_joined("bb");
  this->admit("aa", 1);
  this->clock_.advance(seconds(1));
  this->admit("bb", 2);
  EXPECT_THAT(seqs(this->gate_.take_all()), ::testing::ElementsAre(1u, 2u));
  EXPECT_EQ(this->gate_.held(), 0u);
}

TYPED_TEST(ReplyGateTest, AClientThatNeverMatchesHasAtMostItsCapHeldTheOldestDropped) {
  this->gate_.participant_joined("flood");
  for (std::uint64_t seq = 1; seq <= 3; ++seq) {
    EXPECT_FALSE(this->admit_with("flood", seq).dropped) << "request " << seq;
  }
  for (std::uint64_t seq = 4; seq <= 10; ++seq) {
    const Admission admission = this->admit_with("flood", seq);
    EXPECT_EQ(admission.outcome, GateOutcome::held);
    ASSERT_TRUE(admission.dropped);
    EXPECT_EQ(admission.dropped->client_id, "flood");
    EXPECT_EQ(admission.dropped->request_seq, seq - 3);
    // 1 the first time: the caller logs once per client.
    EXPECT_EQ(admission.dropped->client_drops, seq - 3);
    EXPECT_FALSE(admission.dropped->over_total);
  }
  EXPECT_EQ(this->gate_.held(), 3u);
  EXPECT_EQ(this->gate_.dropped("flood"), 7u);
  EXPECT_EQ(this->gate_.dropped(), 7u);
  // A late reader gets the newest, which its client still waits for.
  EXPECT_THAT(seqs(this->gate_.reader_matched("flood", true)), ::testing::ElementsAre(8u, 9u, 10u));
}

TYPED_TEST(ReplyGateTest, OverTheTotalTheClientHoldingTheMostLosesItsOldestNeverAnothersFew) {
  for (const char* id : {"flood", "slow", "late"}) this->gate_.participant_joined(id);
  this->admit("slow", 1);
  this->admit("flood", 10);
  this->admit("flood", 11);
  this->admit("flood", 12);
  this->admit("late", 20);
  EXPECT_EQ(this->gate_.held(), 5u);
  const Admission admission = this->admit_with("late", 21);
  ASSERT_TRUE(admission.dropped);
  EXPECT_EQ(admission.dropped->client_id, "flood");
  EXPECT_EQ(admission.dropped->request_seq, 10u);
  EXPECT_TRUE(admission.dropped->over_total);
  EXPECT_EQ(this->gate_.held(), 5u);
  EXPECT_EQ(this->gate_.dropped("slow"), 0u);
  EXPECT_THAT(seqs(this->gate_.reader_matched("slow", true)), ::testing::ElementsAre(1u));
  EXPECT_THAT(seqs(this->gate_.reader_matched("late", true)), ::testing::ElementsAre(20u, 21u));
}

TYPED_TEST(ReplyGateTest, HeldRepliesReleasedExpiredOrLeftFreeTheirRoomInTheTotal) {
  for (const char* id : {"aa", "bb", "cc"}) this->gate_.participant_joined(id);
  this->admit("aa", 1);
  this->admit("aa", 2);
  this->admit("bb", 3);
  this->clock_.advance(kHoldLimit);
  this->admit("bb", 4);
  this->admit("cc", 5);
  EXPECT_THAT(seqs(this->gate_.expire()), ::testing::ElementsAre(1u, 2u, 3u));
  this->gate_.reader_matched("bb", true);
  this->gate_.participant_left("cc");
  EXPECT_EQ(this->gate_.held(), 0u);
  this->gate_.participant_joined("dd");
  for (std::uint64_t seq = 6; seq <= 8; ++seq) this->admit("dd", seq);
  this->gate_.participant_joined("ee");
  this->admit("ee", 9);
  this->admit("ee", 10);
  EXPECT_EQ(this->gate_.held(), 5u);
  EXPECT_EQ(this->gate_.dropped(), 0u);
}

}  // namespace
}  // namespace dh3::dds
