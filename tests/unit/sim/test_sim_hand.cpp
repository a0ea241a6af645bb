// The simulated hand, driven with explicit time: every register, initialization
// with and without feedback, motion timing, objects, drops, rotation, the
// settings registers and injected faults.

#include <gtest/gtest.h>

#include <optional>
#include <vector>

#include "dh3/protocol/codec.hpp"
#include "dh3/protocol/registers.hpp"
#include "dh3/sim/sim_hand.hpp"

namespace dh3::sim {
namespace {

using namespace std::chrono_literals;
using protocol::Access;
using protocol::GripStatus;
using protocol::make_read;
using protocol::make_write;
using protocol::Message;
namespace reg = protocol::reg;

constexpr std::int32_t kStatusMoving = 0;
constexpr std::int32_t kStatusArrived = 2;
constexpr std::int32_t kStatusCaught = 3;

class SimHandTest : public ::testing::Test {
 protected:
  SimHandTest() : hand_(make_options(), now_) {}

  static SimHandOptions make_options() {
    SimHandOptions options;
    options.id = 1;
    options.position_speed = 200.0;  // 1 % per 5 ms
    options.rotation_speed = 100.0;  // 1 % per 10 ms
    options.init_time = 300ms;
    options.store_delay = 40ms;
    return options;
  }

  void rebuild(const SimHandOptions& options) { hand_ = SimHand(options, now_); }

  /// Sends a request now and returns the single reply; fails the test if the
  /// hand answers with anything else than exactly one frame.
  Message ask(const Message& request, Duration expected_delay = Duration::zero()) {
    std::vector<Outgoing> replies = hand_.handle(request, now_);
    EXPECT_EQ(replies.size(), 1U) << protocol::describe(request);
    if (replies.empty()) return Message{};
    EXPECT_EQ(replies[0].due, now_ + expected_delay) << protocol::describe(request);
    return replies[0].message;
  }

  std::int32_t read_value(protocol::Register r) { return ask(make_read(1, r)).data; }

  void pass(Duration time) {
    now_ += time;
    unsolicited_ = hand_.advance(now_);
  }

  void initialize() {
    ask(make_write(1, reg::kInitialize, 0));
    pass(300ms);
    ASSERT_TRUE(hand_.initialized());
  }

  TimePoint now_ = TimePoint{} + 1h;
  SimHand hand_;
  std::vector<Outgoing> unsolicited_;
};

// ---------------------------------------------------------------- version

TEST_F(SimHandTest, VersionReadAnswersTheDocumentsBytes) {
  const Message reply = ask(make_read(1, reg::kFirmwareVersion));
  const protocol::BoxFrame expected{0xFF, 0xFE, 0xFD, 0xFC, 0x01, 0x13, 0x01,
                                    0x00, 0x00, 0x00, 0x02, 0x01, 0x04, 0xFB};
  EXPECT_EQ(protocol::encode_box_frame(reply), expected);
}

TEST_F(SimHandTest, VersionComesFromOptions) {
  SimHandOptions options = make_options();
  options.firmware_version = 0x05000100;
  rebuild(options);
  EXPECT_EQ(read_value(reg::kFirmwareVersion), 0x05000100);
}

// ---------------------------------------------------------------- initialization

TEST_F(SimHandTest, InitFeedbackIsOffUntilWrittenAndThenReadsA5) {
  EXPECT_EQ(read_value(reg::kInitFeedback), 0);
  // The document writes 0 and gets A5 back.
  const Message reply = ask(make_write(1, reg::kInitFeedback, 0));
  EXPECT_EQ(reply, (Message{1, reg::kInitFeedback, Access::write, 0, 0xA5}));
  EXPECT_EQ(read_value(reg::kInitFeedback), 0xA5);
  EXPECT_TRUE(hand_.init_feedback_enabled());
}

TEST_F(SimHandTest, InitializeIsEchoedAndFinishesAfterTheInitTime) {
  EXPECT_EQ(read_value(reg::kInitialize), 0) << "a fresh hand is not initialized";
  const Message request = make_write(1, reg::kInitialize, 0);
  EXPECT_EQ(ask(request), request);

  pass(299ms);
  EXPECT_EQ(read_value(reg::kInitialize), 0);
  EXPECT_FALSE(hand_.initialized());
  pass(1ms);
  EXPECT_EQ(read_value(reg::kInitialize), 1);
  EXPECT_TRUE(hand_.initialized());
}

TEST_F(SimHandTest, WithFeedbackTheHandAnnouncesTheEndOfInitialization) {
  ask(make_write(1, reg::kInitFeedback, 0));
  ask(make_write(1, reg::kInitialize, 0));
  const TimePoint done = now_ + 300ms;
  EXPECT_EQ(hand_.next_unsolicited_at(), done);

  pass(299ms);
  EXPECT_TRUE(unsolicited_.empty());
  pass(50ms);  // advanced late: the frame is still stamped with when it was sent
  ASSERT_EQ(unsolicited_.size(), 1U);
  EXPECT_EQ(unsolicited_[0].due, done);
  const protocol::BoxFrame expected{0xFF, 0xFE, 0xFD, 0xFC, 0x01, 0x08, 0x02,
                                    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xFB};
  EXPECT_EQ(protocol::encode_box_frame(unsolicited_[0].message), expected);
  EXPECT_EQ(hand_.next_unsolicited_at(), std::nullopt);
  pass(1s);
  EXPECT_TRUE(unsolicited_.empty()) << "announced once";
}

TEST_F(SimHandTest, WithoutFeedbackInitializationEndsSilently) {
  ask(make_write(1, reg::kInitialize, 0));
  EXPECT_EQ(hand_.next_unsolicited_at(), std::nullopt);
  pass(1s);
  EXPECT_TRUE(unsolicited_.empty());
  EXPECT_TRUE(hand_.initialized());
}

TEST_F(SimHandTest, InitializeWhileInitializingStartsOver) {
  ask(make_write(1, reg::kInitFeedback, 0));
  ask(make_write(1, reg::kInitialize, 0));
  pass(200ms);
  ask(make_write(1, reg::kInitialize, 0));
  pass(200ms);  // 400 ms after the first, 200 ms after the second
  EXPECT_TRUE(unsolicited_.empty());
  EXPECT_EQ(read_value(reg::kInitialize), 0);
  pass(100ms);
  EXPECT_EQ(unsolicited_.size(), 1U);
  EXPECT_EQ(read_value(reg::kInitialize), 1);
}

TEST_F(SimHandTest, InitializationEndsOpenAtHomeWithDefaultStatus) {
  initialize();
  EXPECT_EQ(read_value(reg::kPosition), 100);
  EXPECT_EQ(read_value(reg::kRotation), 0);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);
  EXPECT_EQ(read_value(reg::kRotationStatus), kStatusMoving);
}

TEST_F(SimHandTest, ZeroInitTimeFinishesAtTheNextAdvance) {
  SimHandOptions options = make_options();
  options.init_time = Duration::zero();
  rebuild(options);
  ask(make_write(1, reg::kInitFeedback, 0));
  ask(make_write(1, reg::kInitialize, 0));
  pass(Duration::zero());
  EXPECT_EQ(unsolicited_.size(), 1U);
  EXPECT_TRUE(hand_.initialized());
}

// ---------------------------------------------------------------- force

TEST_F(SimHandTest, ForcesAreStoredAndReadBack) {
  EXPECT_EQ(read_value(reg::kClosingForce), 50);
  EXPECT_EQ(read_value(reg::kOpeningForce), 50);
  const Message set_closing = make_write(1, reg::kClosingForce, 30);
  EXPECT_EQ(ask(set_closing), set_closing);
  const Message set_opening = make_write(1, reg::kOpeningForce, 100);
  EXPECT_EQ(ask(set_opening), set_opening);
  EXPECT_EQ(read_value(reg::kClosingForce), 30);
  EXPECT_EQ(read_value(reg::kOpeningForce), 100);
  EXPECT_EQ(hand_.closing_force(), 30);
  EXPECT_EQ(hand_.opening_force(), 100);
}

TEST_F(SimHandTest, ForceOutOfRangeIsKeptAndAnsweredWithTheKeptValue) {
  ask(make_write(1, reg::kClosingForce, 30));
  for (const std::int32_t bad : {19, 101, -1, 0}) {
    const Message reply = ask(make_write(1, reg::kClosingForce, bad));
    EXPECT_EQ(reply, (Message{1, reg::kClosingForce, Access::write, 0, 30})) << bad;
  }
  EXPECT_EQ(read_value(reg::kClosingForce), 30);
  // The range ends are allowed.
  EXPECT_EQ(ask(make_write(1, reg::kOpeningForce, 20)).data, 20);
  EXPECT_EQ(read_value(reg::kOpeningForce), 20);
}

// ---------------------------------------------------------------- position

TEST_F(SimHandTest, PositionMovesAtTheConfiguredSpeedAndArrives) {
  initialize();
  const Message request = make_write(1, reg::kPosition, 60);
  EXPECT_EQ(ask(request), request);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);

  pass(100ms);  // 200 %/s: 20 % in 100 ms
  EXPECT_EQ(read_value(reg::kPosition), 80);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);
  pass(99ms);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);
  pass(1ms);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
  EXPECT_EQ(read_value(reg::kPosition), 60);
  EXPECT_DOUBLE_EQ(hand_.position(), 60.0);
}

TEST_F(SimHandTest, OpeningMovesUpToo) {
  initialize();
  ask(make_write(1, reg::kPosition, 0));
  pass(500ms);
  EXPECT_EQ(read_value(reg::kPosition), 0);
  ask(make_write(1, reg::kPosition, 40));
  pass(100ms);
  EXPECT_EQ(read_value(reg::kPosition), 20);
  pass(100ms);
  EXPECT_EQ(read_value(reg::kPosition), 40);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
}

TEST_F(SimHandTest, ATargetWhereTheFingersAreArrivesAtOnce) {
  initialize();
  ask(make_write(1, reg::kPosition, 100));
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
}

TEST_F(SimHandTest, ANewTargetInterruptsTheMotion) {
  initialize();
  ask(make_write(1, reg::kPosition, 0));
  pass(100ms);  // at 80
  ask(make_write(1, reg::kPosition, 90));
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);
  pass(50ms);
  EXPECT_EQ(read_value(reg::kPosition), 90);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
}

TEST_F(SimHandTest, MotionBeforeInitializationIsEchoedButNothingMoves) {
  const Message position = make_write(1, reg::kPosition, 30);
  const Message rotation = make_write(1, reg::kRotation, 50);
  EXPECT_EQ(ask(position), position);
  EXPECT_EQ(ask(rotation), rotation);
  pass(2s);
  EXPECT_EQ(read_value(reg::kPosition), 100);
  EXPECT_EQ(read_value(reg::kRotation), 0);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);
  EXPECT_EQ(read_value(reg::kRotationStatus), kStatusMoving);
}

TEST_F(SimHandTest, MotionDuringInitializationIsIgnored) {
  ask(make_write(1, reg::kInitialize, 0));
  pass(100ms);
  const Message position = make_write(1, reg::kPosition, 30);
  EXPECT_EQ(ask(position), position);
  pass(1s);
  EXPECT_TRUE(hand_.initialized());
  EXPECT_EQ(read_value(reg::kPosition), 100);
}

TEST_F(SimHandTest, InitializeStopsARunningMotion) {
  initialize();
  ask(make_write(1, reg::kPosition, 0));
  pass(100ms);
  ask(make_write(1, reg::kInitialize, 0));
  pass(300ms);
  EXPECT_EQ(read_value(reg::kPosition), 100);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);
}

TEST_F(SimHandTest, PositionOutOfRangeDoesNotMoveAndAnswersThePosition) {
  initialize();
  ask(make_write(1, reg::kPosition, 60));
  pass(1s);
  for (const std::int32_t bad : {101, -1, 1000}) {
    const Message reply = ask(make_write(1, reg::kPosition, bad));
    EXPECT_EQ(reply, (Message{1, reg::kPosition, Access::write, 0, 60})) << bad;
  }
  pass(1s);
  EXPECT_EQ(read_value(reg::kPosition), 60);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
}

// ---------------------------------------------------------------- objects

TEST_F(SimHandTest, AnObjectStopsTheClosingFingersWithStatusCaught) {
  SimHandOptions options = make_options();
  options.object_position = 50;
  rebuild(options);
  initialize();
  ask(make_write(1, reg::kPosition, 20));
  pass(249ms);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);
  pass(1ms);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusCaught);
  pass(1s);
  EXPECT_EQ(read_value(reg::kPosition), 50);
  EXPECT_EQ(hand_.grip_status(), GripStatus::caught);
}

TEST_F(SimHandTest, TheGripStatusSaysWhenItChangedEvenIfNobodyAskedThen) {
  // What a benchmark times from: the moment of contact, arrival or drop, not
  // when the model was next advanced.
  SimHandOptions options = make_options();
  options.object_position = 50;
  rebuild(options);
  initialize();
  const TimePoint closing_from = now_;
  ask(make_write(1, reg::kPosition, 20));
  pass(700ms);  // 100 -> 50 at 200 %/s: contact after 250 ms
  EXPECT_EQ(hand_.grip_status(), GripStatus::caught);
  EXPECT_EQ(hand_.grip_status_since(), closing_from + 250ms);
  pass(100ms);
  const TimePoint dropped_at = now_;
  hand_.drop_object();
  EXPECT_EQ(hand_.grip_status_since(), dropped_at);
  pass(1s);  // 50 -> 20: arrives 150 ms after the drop
  EXPECT_EQ(hand_.grip_status(), GripStatus::arrived);
  // Worked out in floating point: to the microsecond.
  EXPECT_LE(std::chrono::abs(hand_.grip_status_since() - (dropped_at + 150ms)), 1us);
}

TEST_F(SimHandTest, ClosingToAboveTheObjectArrives) {
  SimHandOptions options = make_options();
  options.object_position = 50;
  rebuild(options);
  initialize();
  ask(make_write(1, reg::kPosition, 60));
  pass(1s);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
  // Closing exactly to the object's position reaches the target: arrived.
  ask(make_write(1, reg::kPosition, 50));
  pass(1s);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
}

TEST_F(SimHandTest, WithoutAnObjectClosingMisses) {
  initialize();
  ask(make_write(1, reg::kPosition, 0));
  pass(500ms);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
  EXPECT_EQ(read_value(reg::kPosition), 0);
}

TEST_F(SimHandTest, TheObjectStaysForTheNextClosing) {
  initialize();
  hand_.place_object(70);
  ask(make_write(1, reg::kPosition, 10));
  pass(1s);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusCaught);
  ask(make_write(1, reg::kPosition, 100));
  pass(1s);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
  ask(make_write(1, reg::kPosition, 10));
  pass(1s);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusCaught);
  EXPECT_EQ(read_value(reg::kPosition), 70);
}

TEST_F(SimHandTest, ClosingHarderOnAHeldObjectStaysCaught) {
  initialize();
  hand_.place_object(70);
  ask(make_write(1, reg::kPosition, 10));
  pass(1s);
  ask(make_write(1, reg::kPosition, 0));
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusCaught);
  EXPECT_EQ(read_value(reg::kPosition), 70);
}

TEST_F(SimHandTest, FingersBelowAPlacedObjectDoNotJumpBackToIt) {
  initialize();
  ask(make_write(1, reg::kPosition, 0));
  pass(400ms);  // at 20, still closing
  hand_.place_object(50);
  pass(1s);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
  EXPECT_EQ(read_value(reg::kPosition), 0);
}

TEST_F(SimHandTest, ADroppedObjectLetsTheFingersCloseWithoutACommand) {
  initialize();
  hand_.place_object(50);
  ask(make_write(1, reg::kPosition, 20));
  pass(1s);
  ASSERT_EQ(read_value(reg::kGripStatus), kStatusCaught);
  const std::uint64_t requests_before = hand_.requests_seen();

  hand_.drop_object();
  EXPECT_EQ(hand_.grip_status(), GripStatus::moving);
  EXPECT_EQ(hand_.requests_seen(), requests_before);
  pass(100ms);  // 20 % at 200 %/s
  EXPECT_DOUBLE_EQ(hand_.position(), 30.0);
  pass(50ms);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
  EXPECT_EQ(read_value(reg::kPosition), 20);
  EXPECT_EQ(hand_.object_position(), std::nullopt);
}

TEST_F(SimHandTest, MovingTheObjectWhileHoldingItRegrips) {
  initialize();
  hand_.place_object(50);
  ask(make_write(1, reg::kPosition, 20));
  pass(1s);
  hand_.place_object(40);  // the part slipped deeper
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);
  pass(1s);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusCaught);
  EXPECT_EQ(read_value(reg::kPosition), 40);
}

TEST_F(SimHandTest, DroppingWhenNothingIsHeldChangesNoStatus) {
  initialize();
  hand_.place_object(50);
  ask(make_write(1, reg::kPosition, 80));
  pass(1s);
  hand_.drop_object();
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusArrived);
  EXPECT_EQ(read_value(reg::kPosition), 80);
}

// ---------------------------------------------------------------- rotation

TEST_F(SimHandTest, RotationMovesAtItsSpeedWithItsOwnStatus) {
  initialize();
  const Message request = make_write(1, reg::kRotation, 67);
  EXPECT_EQ(ask(request), request);
  pass(300ms);  // 100 %/s
  EXPECT_EQ(read_value(reg::kRotation), 30);
  EXPECT_EQ(read_value(reg::kRotationStatus), kStatusMoving);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving) << "the fingers did not move";
  pass(370ms);
  EXPECT_EQ(read_value(reg::kRotationStatus), kStatusArrived);
  EXPECT_EQ(read_value(reg::kRotation), 67);
}

TEST_F(SimHandTest, AnObstacleBlocksRotationWithStatus3AndCanBeLeft) {
  SimHandOptions options = make_options();
  options.rotation_obstacle = 40;
  rebuild(options);
  initialize();
  ask(make_write(1, reg::kRotation, 67));
  pass(1s);
  EXPECT_EQ(read_value(reg::kRotationStatus), kStatusCaught);
  EXPECT_EQ(read_value(reg::kRotation), 40);
  // Back away from it: free.
  ask(make_write(1, reg::kRotation, 10));
  pass(1s);
  EXPECT_EQ(read_value(reg::kRotationStatus), kStatusArrived);
  EXPECT_EQ(read_value(reg::kRotation), 10);
  // Toward it again: blocked again.
  ask(make_write(1, reg::kRotation, 90));
  pass(1s);
  EXPECT_EQ(read_value(reg::kRotationStatus), kStatusCaught);
  EXPECT_EQ(read_value(reg::kRotation), 40);
  // Blocked at it, pushing further does not pass it.
  ask(make_write(1, reg::kRotation, 100));
  pass(1s);
  EXPECT_EQ(read_value(reg::kRotation), 40);
  EXPECT_EQ(read_value(reg::kRotationStatus), kStatusCaught);
}

TEST_F(SimHandTest, AnObstacleBlocksFromAboveToo) {
  initialize();
  ask(make_write(1, reg::kRotation, 90));
  pass(1s);
  hand_.place_rotation_obstacle(50);
  ask(make_write(1, reg::kRotation, 0));
  pass(2s);
  EXPECT_EQ(read_value(reg::kRotation), 50);
  EXPECT_EQ(read_value(reg::kRotationStatus), kStatusCaught);
  hand_.place_rotation_obstacle(std::nullopt);  // removed: the rotation goes on
  pass(1s);
  EXPECT_EQ(read_value(reg::kRotation), 0);
  EXPECT_EQ(read_value(reg::kRotationStatus), kStatusArrived);
}

TEST_F(SimHandTest, RotationOutOfRangeIsNotApplied) {
  initialize();
  const Message reply = ask(make_write(1, reg::kRotation, 101));
  EXPECT_EQ(reply, (Message{1, reg::kRotation, Access::write, 0, 0}));
  pass(1s);
  EXPECT_EQ(read_value(reg::kRotation), 0);
}

// ---------------------------------------------------------------- status form

TEST_F(SimHandTest, StatusRepliesCarryTheValueInTheDataField) {
  initialize();
  ask(make_write(1, reg::kPosition, 60));
  pass(1s);
  const Message reply = ask(make_read(1, reg::kGripStatus));
  EXPECT_EQ(reply.reserve, 0);
  EXPECT_EQ(reply.data, kStatusArrived);
  const protocol::Payload expected{0x0F, 0x01, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00};
  EXPECT_EQ(protocol::encode_payload(reply), expected);
}

TEST_F(SimHandTest, WritesToReadOnlyRegistersAreAnsweredWithTheirValue) {
  EXPECT_EQ(ask(make_write(1, reg::kFirmwareVersion, 7)).data, 0x04010200);
  EXPECT_EQ(ask(make_write(1, reg::kGripStatus, 3)).data, kStatusMoving);
  EXPECT_EQ(ask(make_write(1, reg::kRotationStatus, 3)).data, kStatusMoving);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);
}

TEST_F(SimHandTest, UnknownRegistersGetNoReply) {
  EXPECT_TRUE(hand_.handle(make_read(1, protocol::Register{0x06, 0x01}), now_).empty());
  EXPECT_TRUE(hand_.handle(make_write(1, protocol::Register{0x20, 0x01}, 1), now_).empty());
  EXPECT_EQ(hand_.requests_seen(), 2U);
}

// ---------------------------------------------------------------- CAN ID, baud

TEST_F(SimHandTest, CanIdWriteIsStoredAnsweredLateAndActiveAfterReboot) {
  const Message request = make_write(1, reg::kCanId, 2);
  EXPECT_EQ(ask(request, 40ms), request);
  EXPECT_EQ(hand_.stored_id(), 2);
  EXPECT_EQ(hand_.id(), 1) << "the new ID needs a reboot";
  // Still answering on 1, and reporting the stored ID.
  EXPECT_EQ(read_value(reg::kCanId), 2);
  EXPECT_TRUE(hand_.handle(make_read(2, reg::kCanId), now_).empty());

  hand_.reboot(now_);
  EXPECT_EQ(hand_.id(), 2);
  EXPECT_TRUE(hand_.handle(make_read(1, reg::kCanId), now_).empty());
  const Message reply = ask(make_read(2, reg::kCanId));
  const protocol::BoxFrame expected{0xFF, 0xFE, 0xFD, 0xFC, 0x02, 0x12, 0x01,
                                    0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0xFB};
  EXPECT_EQ(protocol::encode_box_frame(reply), expected);
}

TEST_F(SimHandTest, IdZeroReachesTheCanIdRegisterOnly) {
  const Message set_with_zero = make_write(0, reg::kCanId, 2);
  EXPECT_EQ(ask(set_with_zero, 40ms), set_with_zero);
  EXPECT_EQ(hand_.stored_id(), 2);
  EXPECT_EQ(ask(make_read(0, reg::kCanId)), (Message{0, reg::kCanId, Access::read, 0, 2}));
  EXPECT_TRUE(hand_.handle(make_read(0, reg::kFirmwareVersion), now_).empty());
  EXPECT_TRUE(hand_.handle(make_write(0, reg::kInitialize, 0), now_).empty());
  EXPECT_FALSE(hand_.initialized());
  EXPECT_EQ(hand_.next_unsolicited_at(), std::nullopt) << "ID 0 must not start initialization";
}

TEST_F(SimHandTest, TheDocumentsReadWithIdZeroAndTheWriteFlagAnswersTheId) {
  ask(make_write(1, reg::kCanId, 2), 40ms);
  hand_.reboot(now_);
  // Document: send 00 12 01 01 00 00 00 00 00, receive 00 12 01 01 00 02 00 00 00.
  const Message reply = ask(Message{0, reg::kCanId, Access::write, 0, 0});
  EXPECT_EQ(reply, (Message{0, reg::kCanId, Access::write, 0, 2}));
  EXPECT_EQ(hand_.stored_id(), 2) << "0 is out of range: not stored";
}

TEST_F(SimHandTest, OtherHandsRequestsAreNotSeen) {
  EXPECT_TRUE(hand_.handle(make_read(5, reg::kFirmwareVersion), now_).empty());
  EXPECT_EQ(hand_.requests_seen(), 0U);
}

TEST_F(SimHandTest, BaudRateIsStoredAndAnsweredLate) {
  EXPECT_EQ(read_value(reg::kBaudRate), 0);
  const Message request = make_write(1, reg::kBaudRate, 2);
  EXPECT_EQ(ask(request, 40ms), request);
  EXPECT_EQ(read_value(reg::kBaudRate), 2);
  // Out of range: answered at once with the kept index.
  EXPECT_EQ(ask(make_write(1, reg::kBaudRate, 6)),
            (Message{1, reg::kBaudRate, Access::write, 0, 2}));
  EXPECT_EQ(hand_.baud_index(), 2);
}

TEST_F(SimHandTest, RebootForgetsInitializationFeedbackAndForcesButNotThePlace) {
  ask(make_write(1, reg::kInitFeedback, 0));
  initialize();
  ask(make_write(1, reg::kClosingForce, 80));
  ask(make_write(1, reg::kPosition, 40));
  pass(1s);
  hand_.reboot(now_);
  EXPECT_FALSE(hand_.initialized());
  EXPECT_EQ(read_value(reg::kInitialize), 0);
  EXPECT_EQ(read_value(reg::kInitFeedback), 0);
  EXPECT_EQ(read_value(reg::kClosingForce), 50);
  EXPECT_EQ(read_value(reg::kPosition), 40);
  EXPECT_EQ(read_value(reg::kGripStatus), kStatusMoving);
}

// ---------------------------------------------------------------- faults

TEST_F(SimHandTest, AMutedHandIgnoresEverythingButKeepsMoving) {
  initialize();
  ask(make_write(1, reg::kPosition, 0));
  hand_.set_muted(true);
  EXPECT_TRUE(hand_.handle(make_read(1, reg::kPosition), now_).empty());
  EXPECT_TRUE(hand_.handle(make_write(1, reg::kClosingForce, 30), now_).empty());
  EXPECT_EQ(hand_.requests_seen(), 4U);  // initialize, position, and the 2 ignored
  pass(1s);
  hand_.set_muted(false);
  EXPECT_EQ(read_value(reg::kPosition), 0);
  EXPECT_EQ(read_value(reg::kClosingForce), 50) << "a muted hand did not apply the write";
}

TEST_F(SimHandTest, AMutedHandDoesNotAnnounceInitialization) {
  ask(make_write(1, reg::kInitFeedback, 0));
  ask(make_write(1, reg::kInitialize, 0));
  hand_.set_muted(true);
  pass(1s);
  EXPECT_TRUE(unsolicited_.empty());
  hand_.set_muted(false);
  pass(1s);
  EXPECT_TRUE(unsolicited_.empty()) << "the announcement is lost, not postponed";
  EXPECT_EQ(read_value(reg::kInitialize), 1);
}

TEST_F(SimHandTest, ReplyDelayPostponesReplies) {
  SimHandOptions options = make_options();
  options.reply_delay = 7ms;
  rebuild(options);
  ask(make_read(1, reg::kFirmwareVersion), 7ms);
  ask(make_write(1, reg::kCanId, 3), 47ms);  // plus the store delay
  hand_.set_reply_delay(20ms);
  ask(make_read(1, reg::kFirmwareVersion), 20ms);
}

TEST_F(SimHandTest, CorruptionFlipsTheLowDataByteOfTheNextReplies) {
  hand_.corrupt_next_replies(2);
  EXPECT_EQ(read_value(reg::kFirmwareVersion), 0x040102FF);
  EXPECT_EQ(read_value(reg::kClosingForce), 50 ^ 0xFF);
  EXPECT_EQ(read_value(reg::kFirmwareVersion), 0x04010200);
}

TEST_F(SimHandTest, CorruptionAlsoHitsTheInitializationFrame) {
  ask(make_write(1, reg::kInitFeedback, 0));
  ask(make_write(1, reg::kInitialize, 0));
  hand_.corrupt_next_replies(1);
  pass(300ms);
  ASSERT_EQ(unsolicited_.size(), 1U);
  EXPECT_EQ(unsolicited_[0].message.data, 0xFF);
}

}  // namespace
}  // namespace dh3::sim
