// Group commands end to end: dh3::Client and dh3ctl against dh3-service, whose
// bus is a transfer box (dh3-sim) behind a recording proxy, so the frames the
// group put on the wire are seen byte for byte.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>

#include "client_fixture.hpp"
#include "dh3/base/host_name.hpp"

namespace dh3::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

/// A frame's CAN ID, as frames_as_hex() spells it.
std::string id_of(const std::string& frame) {
  return frame.substr(12, 2);
}
bool is_position_write(const std::string& frame) {
  // Function 06, sub-function 02, write (01): docs/dh3-protocol.md.
  return frame.substr(15, 8) == "06 02 01";
}

class ClientGroupTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_NE(sim_.port(), 0);
    ASSERT_NE(proxy_.port(), 0);
    ASSERT_TRUE(service_.started());
    ASSERT_TRUE(client_.connected()) << client_.error();
    for (std::uint16_t id : {1, 2, 3}) {
      ASSERT_TRUE(client_.wait_for_hand(box_spec(id), kClientDeadline)) << id;
    }
  }

  static HandAddress box(std::uint16_t id) { return {test_service_name(), "box", id}; }
  static std::string box_spec(std::uint16_t id) {
    return test_service_name() + "/box/" + std::to_string(id);
  }

  std::vector<std::string> frames_since(std::size_t before) {
    auto frames = frames_as_hex(proxy_.sent());
    return {frames.begin() + static_cast<std::ptrdiff_t>(before), frames.end()};
  }
  std::size_t frames_now() { return proxy_.sent().size() / 14; }

  SimProcess sim_{{"--hands", "1,2,3", "--object", "1:40", "--init-time-ms", "50"}};
  RecordingProxy proxy_{sim_.port()};
  TempFile config_{"buses:\n  - name: box\n    spec: " + proxy_.bus_spec() +
                   "\n    hands: [{id: 1}, {id: 2}, {id: 3}]\n"};
  ServiceProcess service_{{"--config", config_.path(), "--log-level", "warn"}};
  Client client_{client_options()};
};

TEST_F(ClientGroupTest, GraspGroupClosesTheHandsBackToBackAndRepliesOnceForAll) {
  const std::vector<HandAddress> hands{box(1), box(2), box(3)};
  const GroupReply init = client_.group(GroupCommand::initialize, hands);
  ASSERT_TRUE(init.ok()) << init.message;
  ASSERT_EQ(init.hands.size(), 3U);

  const std::size_t before = frames_now();
  const GroupReply grasp = client_.group(GroupCommand::grasp, hands, 50);
  ASSERT_TRUE(grasp.ok()) << grasp.message;
  ASSERT_EQ(grasp.hands.size(), 3U);
  EXPECT_EQ(grasp.hands[0].hand, box(1));
  EXPECT_EQ(grasp.hands[0].grasp, GraspOutcome::grasped);
  EXPECT_EQ(grasp.hands[1].grasp, GraspOutcome::missed);
  EXPECT_EQ(grasp.hands[2].grasp, GraspOutcome::missed);

  // The three close frames follow each other on the wire with nothing between.
  const auto frames = frames_since(before);
  std::vector<std::size_t> closes;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (is_position_write(frames[i])) closes.push_back(i);
  }
  ASSERT_EQ(closes.size(), 3U);
  EXPECT_EQ(closes[1], closes[0] + 1);
  EXPECT_EQ(closes[2], closes[0] + 2);
  // Each hand's status shows its own outcome, as after a single grasp.
  EXPECT_TRUE(client_.hand(box(1)).wait_until(
      [](const HandStatus& s) { return s.grip == GripState::grasped; }, kClientDeadline));
}

TEST_F(ClientGroupTest, AGroupsCompletionCallbackGetsItsOneReplyOnTheCallbackThread) {
  std::mutex mutex;
  std::condition_variable changed;
  std::optional<GroupReply> ended;
  std::thread::id status_thread;
  std::thread::id completion_thread;
  Subscription statuses = client_.subscribe_status([&](const HandStatus&) {
    std::lock_guard lock(mutex);
    status_thread = std::this_thread::get_id();
  });
  client_.group_async(GroupCommand::initialize, {box(1), box(2)}, 0, [&](GroupReply reply) {
    // A blocking call from inside the callback: its reply is not held up.
    const GroupReply again = client_.group(GroupCommand::move, {box(1), box(2)}, 30);
    std::lock_guard lock(mutex);
    completion_thread = std::this_thread::get_id();
    ended = std::move(reply);
    ended->message += again.ok() ? "" : "; the blocking move failed: " + again.message;
    changed.notify_all();
  });
  std::unique_lock lock(mutex);
  ASSERT_TRUE(changed.wait_for(lock, kClientDeadline, [&] { return ended.has_value(); }));
  EXPECT_TRUE(ended->ok()) << ended->message;
  EXPECT_EQ(ended->hands.size(), 2U);
  EXPECT_EQ(completion_thread, status_thread);
  EXPECT_NE(completion_thread, std::this_thread::get_id());
}

TEST_F(ClientGroupTest, GroupWithAHandLeasedByAnotherClientSendsNothing) {
  ASSERT_TRUE(client_.group(GroupCommand::initialize, {box(1), box(2)}).ok());
  ClientOptions other_options = client_options();
  other_options.participant_name = "other-program";
  Client other(other_options);
  ASSERT_TRUE(other.wait_for_hand(box_spec(2), kClientDeadline));
  ASSERT_TRUE(other.hand(box(2)).acquire_lease(std::chrono::seconds(60)).ok());

  const std::size_t before = frames_now();
  const GroupReply move = client_.group(GroupCommand::move, {box(1), box(2)}, 20);
  ASSERT_FALSE(move.ok());
  EXPECT_EQ(move.code, Code::denied);
  ASSERT_EQ(move.hands.size(), 2U);
  EXPECT_EQ(move.hands[0].code, Code::cancelled);
  EXPECT_EQ(move.hands[1].code, Code::denied);
  // The holder by the name it announced, never by its id.
  EXPECT_THAT(move.hands[1].message, HasSubstr("'" + program_at_host("other-program") + "'"));
  EXPECT_THAT(move.hands[1].message, Not(HasSubstr(other.client_id())));
  EXPECT_THAT(move.message, HasSubstr("nothing sent"));
  // The service polls meanwhile; no position write to either hand went out.
  for (const auto& frame : frames_since(before)) {
    EXPECT_FALSE(is_position_write(frame)) << "sent to hand " << id_of(frame) << ": " << frame;
  }
  // The lease holder itself may move hand 2 in a group.
  const GroupReply own = other.group(GroupCommand::move, {box(2)}, 30);
  EXPECT_TRUE(own.ok()) << own.message;
}

TEST_F(ClientGroupTest, ANewClientIsSentNoGroupReplyOfAnotherClient) {
  // The service keeps its last group replies for other vendors' readers
  // (TRANSIENT_LOCAL); a dh3 client joining later gets none of them.
  ASSERT_TRUE(client_.group(GroupCommand::initialize, {box(1)}).ok());
  ASSERT_TRUE(client_.group(GroupCommand::move, {box(1)}, 20).ok());
  Client later(client_options());
  ASSERT_TRUE(later.wait_for_hand(box_spec(2), kClientDeadline));
  const GroupReply own = later.group(GroupCommand::initialize, {box(2)});
  ASSERT_TRUE(own.ok()) << own.message;
  EXPECT_EQ(later.command_traffic().own_replies, 1U);
  EXPECT_EQ(later.command_traffic().foreign_replies, 0U);
}

TEST_F(ClientGroupTest, Dh3ctlGroupPrintsALinePerHandAndFailsWhenOneFails) {
  const auto init = dh3ctl({"group", "init", box_spec(1), box_spec(3)});
  ASSERT_EQ(init.exit_code, 0) << init.text();
  const auto grasp = dh3ctl({"group", "grasp", box_spec(1), box_spec(3), "--force", "50"});
  ASSERT_EQ(grasp.exit_code, 0) << grasp.text();
  EXPECT_THAT(grasp.text(), HasSubstr(box_spec(1) + ": GRASPED"));
  EXPECT_THAT(grasp.text(), HasSubstr(box_spec(3) + ": MISSED"));
  // Hand 2 was never initialized: the group is refused, each hand says why.
  const auto refused = dh3ctl({"group", "move", box_spec(1), box_spec(2), "--position", "60"});
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_THAT(refused.text(), HasSubstr(box_spec(2) + ": NOT_INITIALIZED"));
  EXPECT_THAT(refused.text(), HasSubstr(box_spec(1) + ": CANCELLED"));
}

}  // namespace
}  // namespace dh3::test
