// dh3::Client and dh3::Hand against the real dh3-service on the simulator:
// commands and their replies, errors with the service's code and message,
// events, threads, concurrent clients, leases, and the service stopping,
// dying and coming back while the client lives on.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <csignal>
#include <future>
#include <mutex>
#include <thread>

#include "client_fixture.hpp"
#include "dh3/base/host_name.hpp"
#include "dh3/registers.hpp"

namespace dh3::test {
namespace {

using ::testing::AnyOf;
using ::testing::HasSubstr;

class ClientLibraryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    service_ = std::make_unique<RunningService>(sim_config());
    ASSERT_TRUE(service_->started());
    ASSERT_TRUE(client_.connected()) << client_.error();
    auto found = client_.wait_for_service(test_service_name(), kClientDeadline);
    ASSERT_TRUE(found) << found.message();
  }

  Hand hand(std::uint16_t id) {
    auto found = client_.wait_for_hand(hand_spec(id), kClientDeadline);
    EXPECT_TRUE(found) << found.message();
    return found ? *found : client_.hand(hand_address(id));
  }

  std::unique_ptr<RunningService> service_;
  Client client_{client_options()};
};

/// Collects events from a callback; tests wait on what arrived.
class EventLog {
 public:
  void add(const HandEvent& event) {
    {
      std::lock_guard lock(mutex_);
      events_.push_back(event);
    }
    changed_.notify_all();
  }
  bool wait_for_kind(EventKind kind) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, kClientDeadline, [&] {
      return std::any_of(events_.begin(), events_.end(),
                         [&](const HandEvent& e) { return e.kind == kind; });
    });
  }
  std::vector<HandEvent> events() {
    std::lock_guard lock(mutex_);
    return events_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<HandEvent> events_;
};

TEST_F(ClientLibraryTest, ListsTheServiceAndItsHandsWithTheirStatus) {
  ASSERT_TRUE(client_.wait_for_statuses(kClientDeadline));
  const auto info = client_.service(test_service_name());
  ASSERT_TRUE(info);
  EXPECT_TRUE(info->ready);
  ASSERT_EQ(info->buses.size(), 1U);
  EXPECT_EQ(info->buses[0].name, "bus0");
  const auto hands = client_.hands();
  ASSERT_EQ(hands.size(), 3U);
  for (const auto& status : hands) EXPECT_EQ(status.address.service, test_service_name());
  const Hand one = hand(1);
  EXPECT_TRUE(one.wait_until([](const HandStatus& s) { return s.online; }, kClientDeadline));
}

TEST_F(ClientLibraryTest, AStatusSaysWhenItsValuesWereReadAndAtRestThatAdvances) {
  Hand one = hand(1);
  const auto first = one.wait_until(
      [](const HandStatus& s) { return s.online && s.read_at_ns != 0; }, kClientDeadline);
  ASSERT_TRUE(first);
  EXPECT_LE(first->read_at_ns, first->timestamp_ns);
  // Nothing moves, so no value changes; the hand is still read (every 50 ms
  // here), and a sample with the same values says so.
  const auto later = one.wait_until(
      [&](const HandStatus& s) { return s.read_at_ns > first->read_at_ns; }, kClientDeadline);
  ASSERT_TRUE(later);
  EXPECT_LE(later->read_at_ns, later->timestamp_ns);
  EXPECT_EQ(later->position, first->position);
  EXPECT_EQ(later->grip, first->grip);
}

TEST_F(ClientLibraryTest, InitializeMoveGraspAndRelease) {
  Hand one = hand(1);
  const Reply init = one.initialize();
  ASSERT_TRUE(init) << init.message;
  EXPECT_TRUE(one.wait_until([](const HandStatus& s) { return s.initialized; }));

  const Reply move = one.move_to(60);
  ASSERT_TRUE(move) << move.message;
  EXPECT_TRUE(one.wait_until([](const HandStatus& s) {
    return s.position == 60 && s.grip == GripState::arrived;
  })) << "never arrived at 60";

  // Hand 1 has an object at 40: closing from 60 stops on it.
  const Reply grasp = one.grasp(40);
  ASSERT_TRUE(grasp) << grasp.message;
  EXPECT_EQ(grasp.grasp, GraspOutcome::grasped);
  EXPECT_GE(grasp.value, 35);
  EXPECT_LE(grasp.value, 45);
  EXPECT_TRUE(one.wait_until([](const HandStatus& s) { return s.grip == GripState::grasped; }));

  const Reply release = one.release(100);
  ASSERT_TRUE(release) << release.message;
  EXPECT_TRUE(one.wait_until([](const HandStatus& s) { return s.position == 100; }));
}

TEST_F(ClientLibraryTest, GraspOnNothingIsMissedWithTheFinalPosition) {
  Hand two = hand(2);
  ASSERT_TRUE(two.initialize());
  const Reply grasp = two.grasp(30);
  ASSERT_TRUE(grasp) << grasp.message;
  EXPECT_EQ(grasp.grasp, GraspOutcome::missed);
  EXPECT_EQ(grasp.value, 0);
}

TEST_F(ClientLibraryTest, ReadsRotatesAndSetsForces) {
  Hand three = hand(3);
  ASSERT_TRUE(three.initialize());
  const Reply force = three.set_force(70, 30);
  ASSERT_TRUE(force) << force.message;
  EXPECT_TRUE(three.wait_until(
      [](const HandStatus& s) { return s.closing_force == 70 && s.opening_force == 30; }));
  EXPECT_EQ(three.read(reg::closing_force).value, 70);
  EXPECT_EQ(three.read(reg::firmware_version).value, 0x04010200);
  ASSERT_TRUE(three.rotate_to(50));
  EXPECT_TRUE(three.wait_until([](const HandStatus& s) { return s.rotation == 50; }));
  EXPECT_TRUE(three.stop());
}

TEST_F(ClientLibraryTest, ErrorsCarryTheServicesCodeAndMessage) {
  Hand two = hand(2);
  const Reply early = two.move_to(50);
  EXPECT_EQ(early.code, Code::not_initialized);
  EXPECT_THAT(early.message, HasSubstr("not initialized"));

  const Reply unknown = client_.hand(hand_address(9)).initialize();
  EXPECT_EQ(unknown.code, Code::unknown_hand);
  EXPECT_THAT(unknown.message, HasSubstr("no hand 9"));

  const Reply admin = two.set_can_id(5);
  EXPECT_EQ(admin.code, Code::denied);
  EXPECT_THAT(admin.message, HasSubstr("--allow-admin"));

  const Reply bad_bus = client_.hand({test_service_name(), "nobus", 1}).stop();
  EXPECT_EQ(bad_bus.code, Code::unknown_hand);
  EXPECT_THAT(bad_bus.message, HasSubstr("no bus 'nobus'"));
}

TEST_F(ClientLibraryTest, AHandTheServiceDoesNotListIsRefusedWithWhatItLists) {
  // The wait is long on purpose: the service's own list of its hands answers,
  // not the end of the wait, and the answer names the hands there are.
  const auto timeout = std::chrono::seconds(300);
  for (const std::string& spec : {test_service_name() + "/bus0/9", std::string("bus7/1")}) {
    auto found = client_.wait_for_hand(spec, timeout);
    ASSERT_FALSE(found) << spec;
    EXPECT_EQ(found.code(), Code::unknown_hand) << spec;
    EXPECT_THAT(found.message(), HasSubstr(hand_spec(1))) << spec;
  }
}

TEST_F(ClientLibraryTest, ScanFindsTheHandsOnTheBus) {
  const Reply scan = client_.scan(test_service_name(), "bus0");
  ASSERT_TRUE(scan) << scan.message;
  EXPECT_EQ(scan.found_ids, (std::vector<std::uint16_t>{1, 2, 3}));
  const Reply from_hand = hand(2).scan_bus();
  ASSERT_TRUE(from_hand) << from_hand.message;
  EXPECT_EQ(from_hand.found_ids, (std::vector<std::uint16_t>{1, 2, 3}));
}

TEST_F(ClientLibraryTest, EventsReachTheCallback) {
  Hand one = hand(1);
  EventLog log;
  auto subscription = one.subscribe([&log](const HandEvent& e) { log.add(e); });
  ASSERT_TRUE(one.initialize());
  EXPECT_TRUE(log.wait_for_kind(EventKind::initialized));
  ASSERT_TRUE(one.grasp(40));
  EXPECT_TRUE(log.wait_for_kind(EventKind::grasped));
  for (const auto& event : log.events()) EXPECT_EQ(event.hand, hand_address(1));
}

TEST_F(ClientLibraryTest, TwoThreadsDriveTwoHandsAtOnce) {
  std::atomic<int> failures{0};
  const auto drive = [&](std::uint16_t id, std::int32_t low, std::int32_t high) {
    Hand h = client_.hand(hand_address(id));
    if (!h.initialize()) ++failures;
    for (int i = 0; i < 5; ++i) {
      const Reply a = h.move_to(low);
      const Reply b = h.move_to(high);
      if (!a || !b) ++failures;
    }
  };
  std::thread first(drive, std::uint16_t{2}, 20, 80);
  std::thread second(drive, std::uint16_t{3}, 10, 90);
  first.join();
  second.join();
  EXPECT_EQ(failures, 0);
  EXPECT_TRUE(hand(2).wait_until([](const HandStatus& s) { return s.target_position == 80; }));
  EXPECT_TRUE(hand(3).wait_until([](const HandStatus& s) { return s.target_position == 90; }));
}

TEST_F(ClientLibraryTest, OneClientsRepliesNeverResolveAnothersCalls) {
  // Two clients number their requests alike: each must get only its own
  // answers.
  Client other(client_options());
  ASSERT_TRUE(other.wait_for_service(test_service_name(), kClientDeadline));
  Hand mine = hand(1);
  Hand theirs = other.hand(hand_address(1));
  ASSERT_TRUE(mine.initialize());
  ASSERT_TRUE(mine.set_force(70, 30));
  std::atomic<int> wrong{0};
  std::thread reader([&] {
    for (int i = 0; i < 20; ++i) {
      const Reply r = theirs.read(reg::firmware_version);
      if (!r || r.value != 0x04010200) ++wrong;
    }
  });
  for (int i = 0; i < 20; ++i) {
    const Reply r = mine.read(reg::closing_force);
    if (!r || r.value != 70) ++wrong;
  }
  reader.join();
  EXPECT_EQ(wrong, 0);
}

TEST_F(ClientLibraryTest, EachClientReceivesOnlyTheRepliesToItsOwnRequests) {
  // With N clients commanding, a client that received every reply would take
  // N times the replies it needs. The service sends each client its own; a
  // reader of the plain topic (another vendor's participant) still gets all.
  Client other(client_options());
  ASSERT_TRUE(other.wait_for_service(test_service_name(), kClientDeadline));
  DdsTestClient plain(test_domain(), "dh3-plain-reader");
  ASSERT_TRUE(plain.ok());
  ASSERT_TRUE(plain.wait_for_service(test_service_name()));
  const auto before_mine = client_.command_traffic();
  const auto before_theirs = other.command_traffic();
  Hand mine = hand(1);
  Hand theirs = other.hand(hand_address(2));
  constexpr int kCommands = 20;
  std::thread reader([&] {
    for (int i = 0; i < kCommands; ++i) EXPECT_TRUE(theirs.read(reg::closing_force));
  });
  for (int i = 0; i < kCommands; ++i) EXPECT_TRUE(mine.read(reg::closing_force));
  reader.join();
  const auto after_mine = client_.command_traffic();
  const auto after_theirs = other.command_traffic();
  EXPECT_EQ(after_mine.requests_written - before_mine.requests_written, kCommands);
  EXPECT_EQ(after_mine.own_replies - before_mine.own_replies, kCommands);
  EXPECT_EQ(after_mine.foreign_replies - before_mine.foreign_replies, 0U);
  EXPECT_EQ(after_theirs.own_replies - before_theirs.own_replies, kCommands);
  EXPECT_EQ(after_theirs.foreign_replies - before_theirs.foreign_replies, 0U);
  // The plain reader gets both clients' replies (the last ones may still be
  // on their way to it).
  EXPECT_TRUE(plain.wait_replies_to(client_.client_id(), kCommands))
      << plain.replies_to(client_.client_id());
  EXPECT_TRUE(plain.wait_replies_to(other.client_id(), kCommands))
      << plain.replies_to(other.client_id());
}

TEST_F(ClientLibraryTest, WhenAStateChangingReplyArrivesTheCachedStatusAlreadyShowsIt) {
  // The guarantee client.hpp states: no wait_until() needed after the reply.
  Hand mine = hand(1);
  ASSERT_TRUE(mine.initialize());
  for (int i = 0; i < 30; ++i) {
    const std::int32_t force = i % 2 == 0 ? 50 : 60;
    ASSERT_TRUE(mine.set_force(force));
    const auto status = mine.status();
    ASSERT_TRUE(status.has_value());
    EXPECT_EQ(status->closing_force, force) << "after set_force number " << i;
  }
}

TEST_F(ClientLibraryTest, ALeaseHolderKeepsOtherClientsOut) {
  ClientOptions other_options = client_options();
  other_options.participant_name = "other-program";
  Client other(other_options);
  ASSERT_TRUE(other.wait_for_service(test_service_name(), kClientDeadline));
  Hand mine = hand(2);
  Hand theirs = other.hand(hand_address(2));
  ASSERT_TRUE(mine.initialize());
  const Reply lease = mine.acquire_lease(std::chrono::seconds(30));
  ASSERT_TRUE(lease) << lease.message;
  const Reply denied = theirs.move_to(10);
  EXPECT_EQ(denied.code, Code::denied);
  // Shown as "<program>@<host>" (this test's program: no participant_name given).
  EXPECT_EQ(denied.lease_holder, program_at_host(""));
  EXPECT_NE(denied.lease_holder.find('@'), std::string::npos);
  EXPECT_TRUE(mine.move_to(30));
  ASSERT_TRUE(mine.release_lease());
  const Reply allowed = theirs.move_to(10);
  EXPECT_TRUE(allowed) << allowed.message;
}

TEST_F(ClientLibraryTest, ALateJoinerSeesTheLatestStatusAtOnce) {
  ASSERT_TRUE(hand(1).initialize());
  ASSERT_TRUE(hand(1).move_to(70));
  ASSERT_TRUE(hand(1).wait_until([](const HandStatus& s) { return s.position == 70; }));
  Client late(client_options());
  auto found = late.wait_for_hand(hand_spec(1), kClientDeadline);
  ASSERT_TRUE(found) << found.message();
  const auto status = found->status();
  ASSERT_TRUE(status);
  EXPECT_TRUE(status->initialized);
  EXPECT_EQ(status->position, 70);
}

/// The service is replaced while a call is pending: a long initialization
/// keeps the call open.
class ServiceLifecycleTest : public ::testing::Test {
 protected:
  /// Kills `service` with SIGKILL (it says goodbye to nobody) and starts a new
  /// instance of the same service, which is what tells the client.
  static std::unique_ptr<RunningService> kill_and_restart(std::unique_ptr<RunningService> service) {
    service->process().process().send_signal(SIGKILL);
    EXPECT_TRUE(service->process().process().wait_exit(kClientDeadline));
    service.reset();
    auto restarted = std::make_unique<RunningService>(sim_config());
    EXPECT_TRUE(restarted->started());
    return restarted;
  }

  Client client_{client_options()};
};

TEST_F(ServiceLifecycleTest, KilledServiceEndsPendingCallsAndTheSameHandWorksAfterRestart) {
  auto service = std::make_unique<RunningService>(sim_config(/*init_time_ms=*/600000));
  ASSERT_TRUE(service->started());
  auto found = client_.wait_for_hand(hand_spec(1), kClientDeadline);
  ASSERT_TRUE(found) << found.message();
  Hand one = *found;
  EventLog log;
  auto subscription = one.subscribe([&log](const HandEvent& e) { log.add(e); });

  auto pending = one.initialize_async(std::chrono::seconds(120));
  // Requests from one client arrive in order: once another hand's read is
  // answered, the service has the INITIALIZE (which takes ten minutes here).
  const Reply probe = client_.hand(hand_address(3)).read(reg::position);
  ASSERT_TRUE(probe) << probe.message;
  // A new instance of the same service: the client tells it from the dead one.
  const auto restarted = kill_and_restart(std::move(service));
  ASSERT_EQ(pending.wait_for(std::chrono::seconds(60)), std::future_status::ready);
  const Reply lost = pending.get();
  EXPECT_EQ(lost.code, Code::service_lost);
  EXPECT_THAT(lost.message, HasSubstr("INITIALIZE"));

  const Reply again = one.initialize();
  EXPECT_TRUE(again) << again.message;
  EXPECT_TRUE(one.wait_until([](const HandStatus& s) { return s.online && s.initialized; }));
}

TEST_F(ServiceLifecycleTest, KilledServiceEndsAPendingGroupCallServiceLost) {
  auto service = std::make_unique<RunningService>(sim_config(/*init_time_ms=*/600000));
  ASSERT_TRUE(service->started());
  for (std::uint16_t id : {1, 2}) ASSERT_TRUE(client_.wait_for_hand(hand_spec(id), kClientDeadline));
  const std::uint64_t before = client_.command_traffic().requests_written;
  auto pending = client_.group_async(GroupCommand::initialize, {hand_address(1), hand_address(2)},
                                     0, std::chrono::seconds(50));
  // Once the request is out, it is the killed instance's: nothing else can answer it.
  const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
  while (client_.command_traffic().requests_written == before &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_GT(client_.command_traffic().requests_written, before) << "the group request never left";
  const auto restarted = kill_and_restart(std::move(service));
  ASSERT_EQ(pending.wait_for(std::chrono::seconds(60)), std::future_status::ready);
  const GroupReply lost = pending.get();
  EXPECT_EQ(lost.code, Code::service_lost) << lost.message;
  EXPECT_THAT(lost.message, HasSubstr("GROUP INITIALIZE of 2 hand(s)"));
  const GroupReply again = client_.group(GroupCommand::initialize, {hand_address(1), hand_address(2)});
  EXPECT_TRUE(again.ok()) << again.message;
}
TEST_F(ServiceLifecycleTest, StoppedServiceTakesItsHandsOfflineAndComesBack) {
  auto service = std::make_unique<RunningService>(sim_config(/*init_time_ms=*/600000));
  ASSERT_TRUE(service->started());
  auto found = client_.wait_for_hand(hand_spec(2), kClientDeadline);
  ASSERT_TRUE(found) << found.message();
  Hand two = *found;
  ASSERT_TRUE(two.wait_until([](const HandStatus& s) { return s.online; }));
  EventLog log;
  auto subscription = two.subscribe([&log](const HandEvent& e) { log.add(e); });

  auto pending = two.initialize_async(std::chrono::seconds(120));
  // Requests from one client arrive in order: once another hand's read is
  // answered, the service has the INITIALIZE.
  const Reply probe = client_.hand(hand_address(3)).read(reg::position);
  ASSERT_TRUE(probe) << probe.message;
  ASSERT_EQ(service->process().stop(SIGTERM), 0);
  service.reset();

  ASSERT_EQ(pending.wait_for(std::chrono::seconds(60)), std::future_status::ready);
  const Reply ended = pending.get();
  EXPECT_THAT(ended.code, AnyOf(Code::cancelled, Code::service_lost));
  EXPECT_FALSE(ended.message.empty());
  EXPECT_TRUE(two.wait_until([](const HandStatus& s) { return !s.online; }));
  EXPECT_TRUE(log.wait_for_kind(EventKind::offline));
  EXPECT_FALSE(client_.service(test_service_name())->ready);

  // A call made while the service is away waits for it, within its timeout.
  auto waiting = two.read_async(reg::firmware_version, std::chrono::seconds(60));
  RunningService restarted(sim_config());
  ASSERT_TRUE(restarted.started());
  ASSERT_EQ(waiting.wait_for(std::chrono::seconds(60)), std::future_status::ready);
  const Reply read = waiting.get();
  EXPECT_TRUE(read) << read.message;
  EXPECT_EQ(read.value, 0x04010200);
  EXPECT_TRUE(two.wait_until([](const HandStatus& s) { return s.online; }));
  EXPECT_TRUE(two.initialize());
}

TEST(EventWatcherExampleTest, PrintsTheEventsOfTheHandItWatches) {
  RunningService service(sim_config());
  ASSERT_TRUE(service.started());
  Process watcher(EVENT_WATCHER_PATH, {"--domain", std::to_string(test_domain()), hand_spec(1)},
                  Process::Stdin::dev_null);
  ASSERT_TRUE(watcher.wait_for_line("watching events", kClientDeadline));
  // It says so once the service has matched it: no event after this is lost.
  Client client(client_options());
  ASSERT_TRUE(client.wait_for_service(test_service_name(), kClientDeadline));
  ASSERT_TRUE(client.hand(hand_address(1)).initialize());
  const auto line = watcher.wait_for_line(hand_spec(1) + " INITIALIZED", kClientDeadline);
  EXPECT_TRUE(line) << "no INITIALIZED event printed";
  watcher.send_signal(SIGINT);
  const auto status = watcher.wait_exit(kClientDeadline);
  ASSERT_TRUE(status && WIFEXITED(*status));
  EXPECT_EQ(WEXITSTATUS(*status), 0);
}

TEST(PickLoopExampleTest, GraspsAndReleasesTheHandItIsGiven) {
  RunningService service(sim_config());
  ASSERT_TRUE(service.started());
  const Finished run =
      run_program(PICK_LOOP_PATH, {"--domain", std::to_string(test_domain()), "--hand",
                                   hand_spec(1), "--cycles", "2", "--force", "40"});
  ASSERT_EQ(run.exit_code, 0) << run.text();
  EXPECT_THAT(run.text(), HasSubstr("cycle 1: GRASPED"));
  EXPECT_THAT(run.text(), HasSubstr("cycle 2: GRASPED"));
  EXPECT_THAT(run.text(), HasSubstr("done: 2 cycles, 2 grasped"));
}

}  // namespace
}  // namespace dh3::test
