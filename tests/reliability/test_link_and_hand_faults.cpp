// Every request gets exactly one reply while the hand or the link misbehaves:
// a hand that answers after the service gave up on it, the transfer box's TCP
// link cut and restored while commands are pending, and a stream of frames in
// one-byte pieces with junk between them. (A muted hand and a full queue:
// tests/integration/service/test_service_with_sim.cpp.)

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "reliability_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::AnyOf;
using ::testing::Eq;
using ::testing::StartsWith;

/// How many of the frames the service sent so far begin with `prefix`
/// ("FF FE FD FC 01 08 02 01": hand 1's initialize).
std::size_t count_frames(RecordingProxy& proxy, const std::string& prefix) {
  const auto frames = frames_as_hex(proxy.sent());
  return static_cast<std::size_t>(std::count_if(
      frames.begin(), frames.end(), [&](const std::string& f) { return f.starts_with(prefix); }));
}

/// Waits until the service has sent more than `before` frames beginning with
/// `prefix`, for kDdsDeadline and `queued` more (a frame the request may wait
/// behind).
bool wait_frame(RecordingProxy& proxy, const std::string& prefix, std::size_t before,
                std::chrono::milliseconds queued = std::chrono::milliseconds(0)) {
  const auto deadline = std::chrono::steady_clock::now() + kDdsDeadline + queued;
  while (std::chrono::steady_clock::now() < deadline) {
    if (count_frames(proxy, prefix) > before) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // polling, not a wait for time
  }
  return false;
}

using LinkAndHandFaults = BoxTest;

TEST_F(LinkAndHandFaults, AHandAnsweringAfterTheTimeoutGetsOneReplyPerRequest) {
  ASSERT_NO_FATAL_FAILURE(start());
  // Hand 2 answers 250 ms after each request; the service waits 100 ms, so its
  // echoes arrive after the service gave up on them, some while the next
  // request of the same register is pending.
  ASSERT_THAT(sim_->control("delay 2 250"), StartsWith("ok"));
  std::vector<std::uint64_t> late;
  std::vector<std::uint64_t> others;
  for (int i = 0; i < 8; ++i) {
    late.push_back(client_->send(client_->request(hand(2), msg::READ_REGISTER, 0, 0x0602)));
    late.push_back(client_->send(client_->request(hand(2), msg::SET_CLOSING_FORCE, 30 + i)));
    others.push_back(
        client_->send(client_->request(hand(1 + 2 * (i % 2)), msg::READ_REGISTER, 0, 0x1301)));
  }
  for (const auto& reply : expect_one_reply_each(*client_, others)) {
    EXPECT_EQ(reply.code(), msg::OK) << reply.message();
    EXPECT_EQ(reply.value(), 0x04010200);
  }
  for (const auto& reply : expect_one_reply_each(*client_, late)) {
    EXPECT_THAT(reply.code(), AnyOf(Eq(msg::OK), Eq(msg::TIMEOUT))) << reply.message();
    EXPECT_FALSE(reply.code() != msg::OK && reply.message().empty());
  }

  // Once it answers in time again it is back and works.
  ASSERT_THAT(sim_->control("delay 2 0"), StartsWith("ok"));
  EXPECT_TRUE(client_->wait_status(hand(2), [](const auto& s) { return s.online(); }));
  const auto seq = client_->send(client_->request(hand(2), msg::SET_CLOSING_FORCE, 77));
  const auto replies = expect_one_reply_each(*client_, {seq});
  ASSERT_EQ(replies.size(), 1U);
  EXPECT_EQ(replies[0].code(), msg::OK) << replies[0].message();
  const auto read = client_->call(hand(2), msg::READ_REGISTER, 0, 0x0502);
  ASSERT_TRUE(read);
  EXPECT_EQ(read->value(), 77);
}

TEST_F(LinkAndHandFaults, ACutLinkEndsPendingRequestsWithBusDownAndTheHandsReturn) {
  // Initialization never finishes, so hand 1's INITIALIZE is pending when the
  // link goes; hand 2 is muted, so its read is pending too: the service waits
  // long for its echo, or the read would end TIMEOUT before the cut on a slow
  // (sanitized) run.
  BoxOptions options;
  options.init_time_ms = 600000;
  options.reply_timeout_ms = 10000;
  ASSERT_NO_FATAL_FAILURE(start(options));
  const std::string init_frame = "FF FE FD FC 01 08 02 01";
  const std::string read_frame = "FF FE FD FC 02 13 01 00";
  const std::size_t reads_before = count_frames(*proxy_, read_frame);
  ASSERT_THAT(sim_->control("mute 2"), StartsWith("ok"));
  const auto init = client_->send(client_->request(hand(1), msg::INITIALIZE));
  const auto read = client_->send(client_->request(hand(2), msg::READ_REGISTER, 0, 0x1301, 30000));
  ASSERT_TRUE(wait_frame(*proxy_, init_frame, 0)) << "INITIALIZE never reached the box";
  // A status poll of hand 2 sent after the mute holds the hand's one frame in
  // flight for a reply timeout (polls are not re-sent): on a slow run the
  // read arrives after it and goes out once that poll timed out.
  ASSERT_TRUE(wait_frame(*proxy_, read_frame, reads_before,
                         std::chrono::milliseconds(options.reply_timeout_ms)))
      << "the read never reached the box";
  EXPECT_EQ(client_->reply_count(init), 0U);
  EXPECT_EQ(client_->reply_count(read), 0U);
  std::uint64_t last_event = 0;
  for (const auto& event : client_->events()) last_event = std::max(last_event, event.event_seq());
  const int connections = proxy_->connections();

  proxy_->cut();
  for (const auto& reply : expect_one_reply_each(*client_, {init, read})) {
    EXPECT_EQ(reply.code(), msg::BUS_DOWN) << reply.message();
    EXPECT_FALSE(reply.message().empty());
  }
  EXPECT_TRUE(client_->wait_info(service_->name(), [](const msg::ServiceInfo& info) {
    return !info.buses().empty() && !info.buses()[0].link_up();
  }));
  for (std::uint16_t id = 1; id <= 3; ++id) {
    EXPECT_TRUE(client_->wait_status(hand(id), [](const auto& s) { return !s.online(); }))
        << "hand " << id << " still online with the link down";
  }
  // While the link is down, new requests fail at once, one reply each.
  std::vector<std::uint64_t> while_down;
  for (std::uint16_t id = 1; id <= 3; ++id) {
    while_down.push_back(client_->send(client_->request(hand(id), msg::READ_REGISTER, 0, 0x0602)));
  }
  for (const auto& reply : expect_one_reply_each(*client_, while_down)) {
    EXPECT_EQ(reply.code(), msg::BUS_DOWN) << reply.message();
  }

  ASSERT_THAT(sim_->control("unmute 2"), StartsWith("ok"));
  proxy_->restore();
  // While cut, the proxy accepts and drops every connection, so the link may
  // have flapped up for a moment just before restore(): wait for a connection
  // the restored proxy kept, then for the link to be reported up.
  const auto deadline = std::chrono::steady_clock::now() + kDdsDeadline;
  while (proxy_->connections() <= connections && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // polling, not a wait for time
  }
  EXPECT_GT(proxy_->connections(), connections) << "the service never reconnected";
  EXPECT_TRUE(client_->wait_info(service_->name(), [](const msg::ServiceInfo& info) {
    return !info.buses().empty() && info.buses()[0].link_up();
  }));
  for (std::uint16_t id = 1; id <= 3; ++id) {
    EXPECT_TRUE(client_->wait_status(hand(id), [](const auto& s) { return s.online(); }))
        << "hand " << id << " not back online";
    EXPECT_TRUE(client_->wait_event([&](const msg::HandEvent& e) {
      return e.event_seq() > last_event && e.kind() == msg::EVENT_ONLINE && e.hand().can_id() == id;
    })) << "no ONLINE event for hand "
        << id;
  }
  std::vector<std::uint64_t> after;
  for (std::uint16_t id = 1; id <= 3; ++id) {
    after.push_back(client_->send(client_->request(hand(id), msg::SET_OPENING_FORCE, 40 + id)));
    after.push_back(client_->send(client_->request(hand(id), msg::READ_REGISTER, 0, 0x0503)));
  }
  const auto replies = expect_one_reply_each(*client_, after);
  ASSERT_EQ(replies.size(), after.size());
  for (std::size_t i = 0; i < replies.size(); ++i) {
    EXPECT_EQ(replies[i].code(), msg::OK) << replies[i].message();
  }
  EXPECT_EQ(replies[1].value(), 41);
  EXPECT_EQ(replies[5].value(), 43);
}

class SplitAndGarbage : public BoxTest {
 protected:
  void before_start() override {
    proxy_->set_split(true);
    proxy_->set_garbage(true);
  }
};

TEST_F(SplitAndGarbage, CommandsSucceedWithOneReplyEach) {
  BoxOptions options;
  options.sim_args = {"--object", "1:40"};
  ASSERT_NO_FATAL_FAILURE(start(options));
  for (std::uint16_t id = 1; id <= 3; ++id) {
    const auto init = client_->call(hand(id), msg::INITIALIZE);
    ASSERT_TRUE(init);
    ASSERT_EQ(init->code(), msg::OK) << init->message();
  }
  std::vector<std::uint64_t> seqs;
  std::vector<msg::CommandType> kinds;
  const auto send = [&](std::uint16_t id, msg::CommandType command, std::int32_t value,
                        std::uint16_t reg = 0) {
    seqs.push_back(client_->send(client_->request(hand(id), command, value, reg)));
    kinds.push_back(command);
  };
  for (std::uint16_t id = 1; id <= 3; ++id) {
    send(id, msg::SET_CLOSING_FORCE, 20 + 10 * id);
    send(id, msg::READ_REGISTER, 0, 0x0502);
    send(id, msg::ROTATE, 25 * id);
    send(id, msg::READ_REGISTER, 0, 0x1301);
  }
  send(1, msg::GRASP, 50);
  send(2, msg::RELEASE, 60);
  send(3, msg::MOVE, 10);
  const auto replies = expect_one_reply_each(*client_, seqs);
  ASSERT_EQ(replies.size(), seqs.size());
  for (std::size_t i = 0; i < replies.size(); ++i) {
    EXPECT_EQ(replies[i].code(), msg::OK) << i << ": " << replies[i].message();
    EXPECT_EQ(replies[i].command(), kinds[i]);
  }
  // The values read came through the mangled stream intact.
  EXPECT_EQ(replies[1].value(), 30);
  EXPECT_EQ(replies[5].value(), 40);
  EXPECT_EQ(replies[9].value(), 50);
  EXPECT_EQ(replies[3].value(), 0x04010200);
  EXPECT_EQ(replies[12].grasp(), msg::GRASPED);
  EXPECT_EQ(replies[12].value(), 40);
  EXPECT_TRUE(client_->wait_status(hand(2), [](const auto& s) { return s.position() == 60; }));
  EXPECT_GT(proxy_->garbage_sent(), 0U);
  EXPECT_TRUE(service_alive());
}

}  // namespace
}  // namespace dh3::test
