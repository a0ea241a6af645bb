// The bytes on the wire: dh3-service talks to a transfer box (dh3-sim) through
// a recording proxy, and every command must put exactly the frames the DH-3
// protocol document describes on the line, nothing for refused requests. The
// expected frames are written out byte for byte from the document, not built
// with the project's codec.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "service_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::Contains;
using ::testing::ElementsAreArray;
using ::testing::IsEmpty;

std::vector<std::string> writes(const std::vector<std::string>& frames) {
  return written_frames(frames);
}

class ServiceFramesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_NE(sim_.port(), 0);
    ASSERT_NE(proxy_.port(), 0);
    ASSERT_TRUE(service_.started());
    client_ = connected_client(service_.name());
    ASSERT_TRUE(client_);
    ASSERT_TRUE(client_->wait_status(hand_, [](const auto& s) { return s.online(); }));
  }

  /// Sends a command, expects `code`, and returns the frames the service sent
  /// to the box meanwhile.
  std::vector<std::string> frames_of(msg::CommandType command, std::int32_t value = 0,
                                     std::uint16_t reg = 0, msg::ResultCode code = msg::OK) {
    const std::size_t before = proxy_.sent().size() / 14;
    const auto reply = client_->call(hand_, command, value, reg);
    EXPECT_TRUE(reply);
    if (reply) {
      EXPECT_EQ(reply->code(), code) << reply->message();
    }
    auto frames = frames_as_hex(proxy_.sent());
    return {frames.begin() + static_cast<std::ptrdiff_t>(before), frames.end()};
  }

  SimProcess sim_{{"--hands", "1", "--object", "1:40", "--init-time-ms", "50"}};
  RecordingProxy proxy_{sim_.port()};
  TempFile config_{"allow_admin: true\nbuses:\n  - name: box\n    spec: " + proxy_.bus_spec() +
                   "\n    command_interval_ms: 2\n    hands: [{id: 1}]\n"};
  ServiceProcess service_{{"--config", config_.path()}};
  std::unique_ptr<DdsTestClient> client_;
  msg::HandAddress hand_ = DdsTestClient::hand(service_.name(), "box", 1);
};

TEST_F(ServiceFramesTest, EveryCommandSendsTheDocumentsFrames) {
  // Initialization: enable the feedback, then initialize (document examples).
  EXPECT_THAT(writes(frames_of(msg::INITIALIZE)),
              ElementsAreArray({"FF FE FD FC 01 08 01 01 00 00 00 00 00 FB",
                                "FF FE FD FC 01 08 02 01 00 00 00 00 00 FB"}));
  EXPECT_THAT(writes(frames_of(msg::ENABLE_INIT_FEEDBACK)),
              ElementsAreArray({"FF FE FD FC 01 08 01 01 00 00 00 00 00 FB"}));
  EXPECT_THAT(writes(frames_of(msg::SET_CLOSING_FORCE, 30)),
              ElementsAreArray({"FF FE FD FC 01 05 02 01 00 1E 00 00 00 FB"}));
  EXPECT_THAT(writes(frames_of(msg::SET_OPENING_FORCE, 30)),
              ElementsAreArray({"FF FE FD FC 01 05 03 01 00 1E 00 00 00 FB"}));
  EXPECT_THAT(writes(frames_of(msg::MOVE, 60)),
              ElementsAreArray({"FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB"}));
  EXPECT_THAT(writes(frames_of(msg::ROTATE, 67)),
              ElementsAreArray({"FF FE FD FC 01 07 02 01 00 43 00 00 00 FB"}));

  const auto version = frames_of(msg::READ_REGISTER, 0, 0x1301);
  EXPECT_THAT(version, Contains("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"));
  EXPECT_THAT(writes(version), IsEmpty());
  const auto force = frames_of(msg::READ_REGISTER, 0, 0x0502);
  EXPECT_THAT(force, Contains("FF FE FD FC 01 05 02 00 00 00 00 00 00 FB"));

  EXPECT_THAT(writes(frames_of(msg::SET_BAUD_RATE, 2)),
              ElementsAreArray({"FF FE FD FC 01 14 01 01 00 02 00 00 00 FB"}));
  EXPECT_THAT(writes(frames_of(msg::SET_CAN_ID, 2)),
              ElementsAreArray({"FF FE FD FC 01 12 01 01 00 02 00 00 00 FB"}));
}

TEST_F(ServiceFramesTest, GraspAndReleaseSendForceAndPosition) {
  ASSERT_EQ(client_->call(hand_, msg::INITIALIZE)->code(), msg::OK);
  // Grasp with 30 %: the closing force, then close fully; the object stops it.
  EXPECT_THAT(writes(frames_of(msg::GRASP, 30)),
              ElementsAreArray({"FF FE FD FC 01 05 02 01 00 1E 00 00 00 FB",
                                "FF FE FD FC 01 06 02 01 00 00 00 00 00 FB"}));
  EXPECT_THAT(writes(frames_of(msg::RELEASE, 100)),
              ElementsAreArray({"FF FE FD FC 01 06 02 01 00 64 00 00 00 FB"}));
}

TEST_F(ServiceFramesTest, StopAtRestReadsWhereTheHandIsAndMovesNothing) {
  ASSERT_EQ(client_->call(hand_, msg::INITIALIZE)->code(), msg::OK);
  ASSERT_EQ(client_->call(hand_, msg::MOVE, 60)->code(), msg::OK);
  ASSERT_EQ(client_->call(hand_, msg::ROTATE, 67)->code(), msg::OK);
  ASSERT_TRUE(client_->wait_status(
      hand_, [](const auto& s) {
        // At rest, not only there: the position is also read during a motion,
        // and a stop during one writes that place back.
        return s.position() == 60 && s.rotation() == 67 && s.grip() == msg::GRIP_ARRIVED &&
               s.rotation_state() == msg::ROTATION_ARRIVED;
      }));
  // A stop reads where the fingers and the rotation are; at rest there is no
  // motion to hold, so nothing is written (a stop during a motion writes that
  // place back: BusSchedulerCommands' stop tests).
  const auto frames = frames_of(msg::STOP);
  EXPECT_THAT(frames, Contains("FF FE FD FC 01 06 02 00 00 00 00 00 00 FB"));
  EXPECT_THAT(frames, Contains("FF FE FD FC 01 07 02 00 00 00 00 00 00 FB"));
  EXPECT_THAT(writes(frames), IsEmpty());
}

TEST_F(ServiceFramesTest, StatusIsPolledWithTheDocumentsReads) {
  ASSERT_EQ(client_->call(hand_, msg::INITIALIZE)->code(), msg::OK);
  // 60: above the object at 40, so the fingers arrive there.
  ASSERT_EQ(client_->call(hand_, msg::MOVE, 60)->code(), msg::OK);
  ASSERT_TRUE(client_->wait_status(hand_, [](const auto& s) { return s.position() == 60; }));
  const auto frames = frames_as_hex(proxy_.sent());
  EXPECT_THAT(frames, Contains("FF FE FD FC 01 06 02 00 00 00 00 00 00 FB"));  // position
  EXPECT_THAT(frames, Contains("FF FE FD FC 01 0F 01 00 00 00 00 00 00 FB"));  // grip status
}

TEST_F(ServiceFramesTest, RefusedRequestsNeverReachTheBus) {
  ASSERT_EQ(client_->call(hand_, msg::INITIALIZE)->code(), msg::OK);
  const std::size_t before = proxy_.sent().size() / 14;
  for (const auto& [command, value] :
       std::vector<std::pair<msg::CommandType, std::int32_t>>{{msg::MOVE, 101},
                                                              {msg::MOVE, -5},
                                                              {msg::GRASP, 10},
                                                              {msg::ROTATE, 300},
                                                              {msg::SET_CLOSING_FORCE, 0},
                                                              {msg::SET_CAN_ID, 0},
                                                              {msg::SET_BAUD_RATE, 9}}) {
    const auto reply = client_->call(hand_, command, value);
    ASSERT_TRUE(reply);
    EXPECT_EQ(reply->code(), msg::INVALID_ARGUMENT);
  }
  // A valid write afterwards: everything before it has been sent by then.
  ASSERT_EQ(client_->call(hand_, msg::MOVE, 50)->code(), msg::OK);
  auto frames = frames_as_hex(proxy_.sent());
  frames.erase(frames.begin(), frames.begin() + static_cast<std::ptrdiff_t>(before));
  EXPECT_THAT(writes(frames), ElementsAreArray({"FF FE FD FC 01 06 02 01 00 32 00 00 00 FB"}));
}

TEST_F(ServiceFramesTest, EveryFrameIsWellFormed) {
  ASSERT_EQ(client_->call(hand_, msg::INITIALIZE)->code(), msg::OK);
  ASSERT_EQ(client_->call(hand_, msg::GRASP, 50)->code(), msg::OK);
  const auto bytes = proxy_.sent();
  ASSERT_EQ(bytes.size() % 14, 0U);
  for (const auto& frame : frames_as_hex(bytes)) {
    EXPECT_EQ(frame.substr(0, 11), "FF FE FD FC") << frame;
    EXPECT_EQ(frame.substr(12, 2), "01") << frame;  // the only hand
    EXPECT_TRUE(frame.substr(21, 2) == "00" || frame.substr(21, 2) == "01") << frame;
    EXPECT_EQ(frame.substr(24, 2), "00") << frame;  // reserve
    EXPECT_EQ(frame.substr(39, 2), "FB") << frame;
  }
}

}  // namespace
}  // namespace dh3::test
