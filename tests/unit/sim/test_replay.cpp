// The replay model: a recording read into per-hand, per-register reply queues
// split at each write (ReplayScript), and the hands answering from them
// (ReplayHands).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "dh3/bus/candump_log.hpp"
#include "dh3/sim/replay_hands.hpp"
#include "dh3/sim/replay_script.hpp"

namespace dh3::sim {
namespace {

using namespace std::chrono_literals;
using protocol::Message;
namespace reg = protocol::reg;

/// Builds a recording line by line, time advancing by what each call says.
class Recording {
 public:
  Recording& sent(const Message& m, Duration after = 1ms) { return add(m, after, "T"); }
  Recording& received(const Message& m, Duration after = 1ms) { return add(m, after, "R"); }
  Recording& line(const std::string& text) {
    text_ += text + "\n";
    return *this;
  }
  [[nodiscard]] const std::string& text() const { return text_; }

 private:
  Recording& add(const Message& m, Duration after, const char* direction) {
    now_ += after;
    bus::LoggedFrame frame;
    frame.time = bus::WallTime(std::chrono::duration_cast<bus::WallTime::duration>(now_));
    frame.direction = direction[0] == 'T' ? bus::FrameDirection::sent
                                          : bus::FrameDirection::received;
    frame.frame.id = m.hand_id;
    const auto payload = protocol::encode_payload(m);
    std::copy(payload.begin(), payload.end(), frame.frame.data.begin());
    text_ += bus::format_log_line(frame, "bus0");
    return *this;
  }
  Duration now_ = std::chrono::seconds(1'700'000'000);
  std::string text_;
};

Message read(std::uint8_t id, protocol::Register r) { return protocol::make_read(id, r); }
Message value(std::uint8_t id, protocol::Register r, std::int32_t v) {
  return Message{id, r, protocol::Access::read, 0, v};
}
Message write(std::uint8_t id, protocol::Register r, std::int32_t v) {
  return protocol::make_write(id, r, v);
}

ReplayScript parse_ok(const Recording& recording) {
  auto script = ReplayScript::parse(recording.text());
  EXPECT_TRUE(script) << (script ? "" : script.error());
  return script ? std::move(*script) : ReplayScript{};
}

/// Delivers one request at `now` and returns the replies' data fields.
std::vector<std::int32_t> ask(ReplayHands& hands, const Message& request, TimePoint now) {
  std::vector<Outgoing> replies;
  std::vector<Outgoing> unasked;
  hands.deliver(request, now, replies, unasked);
  std::vector<std::int32_t> out;
  for (const Outgoing& reply : replies) out.push_back(reply.message.data);
  return out;
}

const TimePoint kStart = TimePoint{} + 1h;

TEST(ReplayScript, RepliesGoToTheirRegisterInOrderAndWritesSplitEpochs) {
  Recording r;
  r.sent(read(1, reg::kGripStatus)).received(value(1, reg::kGripStatus, 2), 2ms);
  r.sent(write(1, reg::kPosition, 40)).received(write(1, reg::kPosition, 40), 3ms);
  r.sent(read(1, reg::kGripStatus)).received(value(1, reg::kGripStatus, 0));
  r.sent(read(1, reg::kPosition)).received(value(1, reg::kPosition, 70));
  r.sent(read(1, reg::kGripStatus)).received(value(1, reg::kGripStatus, 3));
  const ReplayScript script = parse_ok(r);
  EXPECT_EQ(script.device(), "bus0");
  EXPECT_EQ(script.frames(), 10u);
  ASSERT_EQ(script.hands().size(), 1u);
  const RecordedHand& hand = script.hands().at(1);
  ASSERT_EQ(hand.epochs.size(), 2u);
  const auto& before = hand.epochs[0].reads.at(reg::kGripStatus.code());
  ASSERT_EQ(before.size(), 1u);
  EXPECT_EQ(before[0].message.data, 2);
  EXPECT_EQ(before[0].latency, 2ms);
  const auto& after = hand.epochs[1].reads.at(reg::kGripStatus.code());
  ASSERT_EQ(after.size(), 2u);
  EXPECT_EQ(after[0].message.data, 0);
  EXPECT_EQ(after[1].message.data, 3);
  EXPECT_EQ(hand.epochs[1].reads.at(reg::kPosition.code()).at(0).message.data, 70);
  ASSERT_EQ(hand.writes.at(reg::kPosition.code()).size(), 1u);
  EXPECT_EQ(hand.writes.at(reg::kPosition.code())[0].latency, 3ms);
}

TEST(ReplayScript, AFrameNobodyAskedForIsUnaskedWithItsOffsetFromTheWrite) {
  Recording r;
  r.sent(write(2, reg::kInitFeedback, 0)).received(value(2, reg::kInitFeedback, 0xA5));
  r.sent(write(2, reg::kInitialize, 1), 5ms).received(write(2, reg::kInitialize, 1), 1ms);
  r.received(value(2, reg::kInitialize, 0), 299ms);  // the initialization feedback
  const ReplayScript script = parse_ok(r);
  const RecordedHand& hand = script.hands().at(2);
  ASSERT_EQ(hand.epochs.size(), 3u);
  ASSERT_EQ(hand.epochs[2].unasked.size(), 1u);
  EXPECT_EQ(hand.epochs[2].unasked[0].offset, 300ms);
  EXPECT_EQ(hand.epochs[2].unasked[0].message.reg, reg::kInitialize);
}

TEST(ReplayScript, HandsThatNeverAnsweredAreNotReplayed) {
  Recording r;
  r.sent(read(9, reg::kFirmwareVersion)).sent(read(10, reg::kFirmwareVersion));
  r.received(value(10, reg::kFirmwareVersion, 0x04010200));
  const ReplayScript script = parse_ok(r);
  ASSERT_EQ(script.hands().size(), 1u);
  EXPECT_EQ(script.hands().begin()->first, 10);
}

TEST(ReplayScript, CommentsAndFramesNoHandSendsAreSkipped) {
  Recording r;
  r.line("# recorded on the cell").line("(1700000000.000000) bus0 12345678#00 R");
  r.line("(1700000000.000001) bus0 001#0102 R");  // not 8 bytes: no DH-3 message
  r.sent(read(1, reg::kPosition)).received(value(1, reg::kPosition, 5));
  const ReplayScript script = parse_ok(r);
  EXPECT_EQ(script.frames(), 2u);
  EXPECT_EQ(script.skipped(), 2u);
}

TEST(ReplayScript, BadRecordingsAreRefusedNamingTheLine) {
  auto broken = ReplayScript::parse("(1700000000.000000) bus0 001#0F01000000000000 T\n(17x\n");
  ASSERT_FALSE(broken);
  EXPECT_NE(broken.error().find("line 2"), std::string::npos) << broken.error();
  auto undirected = ReplayScript::parse("(1700000000.000000) bus0 001#0F01000000000000\n");
  ASSERT_FALSE(undirected);
  EXPECT_NE(undirected.error().find("direction"), std::string::npos) << undirected.error();
  auto two_buses = ReplayScript::parse(
      "(1.000000) a 001#0F01000000000000 T\n(2.000000) b 001#0F01000000000000 R\n");
  ASSERT_FALSE(two_buses);
  EXPECT_NE(two_buses.error().find("'b'"), std::string::npos) << two_buses.error();
}

TEST(ReplayHands, AnswersEachRegisterInTheRecordedOrderAfterTheRecordedLatency) {
  Recording r;
  r.sent(read(1, reg::kPosition)).received(value(1, reg::kPosition, 100), 4ms);
  r.sent(read(1, reg::kPosition)).received(value(1, reg::kPosition, 90));
  const ReplayScript script = parse_ok(r);
  ReplayHands hands(script, kStart);
  EXPECT_EQ(hands.ids(), std::vector<std::uint8_t>{1});
  std::vector<Outgoing> replies;
  std::vector<Outgoing> unasked;
  EXPECT_EQ(hands.deliver(read(1, reg::kPosition), kStart, replies, unasked), 1u);
  ASSERT_EQ(replies.size(), 1u);
  EXPECT_EQ(replies[0].due, kStart + 4ms);
  EXPECT_EQ(replies[0].message, value(1, reg::kPosition, 100));
  EXPECT_EQ(ask(hands, read(1, reg::kPosition), kStart), std::vector<std::int32_t>{90});
  // Used up: the hand stays where it was last seen.
  EXPECT_EQ(ask(hands, read(1, reg::kPosition), kStart), std::vector<std::int32_t>{90});
}

TEST(ReplayHands, AWriteSkipsWhatTheReplayDidNotReadBeforeIt) {
  Recording r;
  r.sent(write(1, reg::kPosition, 0)).received(write(1, reg::kPosition, 0));
  for (const std::int32_t status : {0, 0, 0, 3}) {  // a grasp that catches
    r.sent(read(1, reg::kGripStatus)).received(value(1, reg::kGripStatus, status));
  }
  r.sent(write(1, reg::kPosition, 100)).received(write(1, reg::kPosition, 100));
  for (const std::int32_t status : {0, 2}) {  // a release that arrives
    r.sent(read(1, reg::kGripStatus)).received(value(1, reg::kGripStatus, status));
  }
  const ReplayScript script = parse_ok(r);
  ReplayHands hands(script, kStart);
  EXPECT_EQ(ask(hands, write(1, reg::kPosition, 0), kStart), std::vector<std::int32_t>{0});
  EXPECT_EQ(ask(hands, read(1, reg::kGripStatus), kStart), std::vector<std::int32_t>{0});
  // The replay releases after one read: the rest of the grasp is not replayed into it.
  EXPECT_EQ(ask(hands, write(1, reg::kPosition, 100), kStart), std::vector<std::int32_t>{100});
  EXPECT_EQ(ask(hands, read(1, reg::kGripStatus), kStart), std::vector<std::int32_t>{0});
  EXPECT_EQ(ask(hands, read(1, reg::kGripStatus), kStart), std::vector<std::int32_t>{2});
}

TEST(ReplayHands, ARegisterSkippedByAWriteHoldsItsLastRecordedValue) {
  Recording r;
  r.sent(read(1, reg::kRotation)).received(value(1, reg::kRotation, 10));
  r.sent(read(1, reg::kRotation)).received(value(1, reg::kRotation, 30));
  r.sent(write(1, reg::kClosingForce, 50)).received(write(1, reg::kClosingForce, 50));
  const ReplayScript script = parse_ok(r);
  ReplayHands hands(script, kStart);
  EXPECT_EQ(ask(hands, write(1, reg::kClosingForce, 50), kStart), std::vector<std::int32_t>{50});
  EXPECT_EQ(ask(hands, read(1, reg::kRotation), kStart), std::vector<std::int32_t>{30});
}

TEST(ReplayHands, UnaskedFramesComeAtTheirOffsetAfterTheirWrite) {
  Recording r;
  r.sent(write(2, reg::kInitialize, 1)).received(write(2, reg::kInitialize, 1), 1ms);
  r.received(value(2, reg::kInitialize, 0), 299ms);
  const ReplayScript script = parse_ok(r);
  ReplayHands hands(script, kStart);
  EXPECT_FALSE(hands.next_unsolicited_at().has_value());
  const TimePoint written = kStart + 5s;
  ask(hands, write(2, reg::kInitialize, 1), written);
  ASSERT_TRUE(hands.next_unsolicited_at().has_value());
  EXPECT_EQ(*hands.next_unsolicited_at(), written + 300ms);
  std::vector<Outgoing> out;
  hands.advance_all(written + 299ms, out);
  EXPECT_TRUE(out.empty());
  hands.advance_all(written + 300ms, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].message, value(2, reg::kInitialize, 0));
  EXPECT_FALSE(hands.next_unsolicited_at().has_value());
}

TEST(ReplayHands, UnknownHandsAndNeverAnsweredRegistersGetNoReply) {
  Recording r;
  r.sent(read(1, reg::kPosition)).received(value(1, reg::kPosition, 100));
  const ReplayScript script = parse_ok(r);
  ReplayHands hands(script, kStart);
  std::vector<Outgoing> replies;
  std::vector<Outgoing> unasked;
  EXPECT_EQ(hands.deliver(read(7, reg::kPosition), kStart, replies, unasked), 0u);
  EXPECT_TRUE(ask(hands, read(1, reg::kFirmwareVersion), kStart).empty());
  // A write nobody recorded is acknowledged, as every hand does.
  EXPECT_EQ(ask(hands, write(1, reg::kOpeningForce, 60), kStart), std::vector<std::int32_t>{60});
}

}  // namespace
}  // namespace dh3::sim
