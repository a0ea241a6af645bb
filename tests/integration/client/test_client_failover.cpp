// A service killed, frozen or duplicated, as the client library, dh3ctl and a
// second dh3-service see it (docs/failover.md). Deaths must be seen well
// before Fast DDS's 20 s participant lease would have told: the deadlines
// below are generous for a loaded machine and still inside that lease, so a
// client that fell back on the participant lease fails them.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

#include "client_fixture.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/contract/participant.hpp"
#include "dh3/contract/qos.hpp"
#include "dh3/registers.hpp"

namespace dh3::test {
namespace {

using ::testing::AnyOf;
using ::testing::HasSubstr;

/// Inside the 20 s participant lease, whatever the machine's load.
constexpr std::chrono::seconds kBeforeParticipantLease{12};

/// The OFFLINE events a hand's subscription got.
class OfflineLog {
 public:
  void add(const HandEvent& event) {
    if (event.kind != EventKind::offline) return;
    std::lock_guard lock(mutex_);
    messages_.push_back(event.message);
    changed_.notify_all();
  }
  std::optional<std::string> wait(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    if (!changed_.wait_for(lock, timeout, [this] { return !messages_.empty(); })) return {};
    return messages_.front();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::string> messages_;
};

/// Reads lines until one contains `text`; nullopt at end of file or timeout.
std::optional<std::string> wait_for_text(Process& process, std::string_view text,
                                         std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    auto line = process.read_line(std::max(left, std::chrono::milliseconds(0)));
    if (!line || line->find(text) != std::string::npos) return line;
  }
}

class FailoverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(service_->started());
    auto found = client_.wait_for_hand(hand_spec(2), kClientDeadline);
    ASSERT_TRUE(found) << found.message();
    hand_.emplace(*found);
    ASSERT_TRUE(hand_->wait_until([](const HandStatus& s) { return s.online; }));
    subscription_ = hand_->subscribe([this](const HandEvent& e) { offline_.add(e); });
  }

  /// An INITIALIZE that stays in flight (initialization takes ten minutes here).
  std::future<Reply> command_in_flight() {
    auto pending = hand_->initialize_async(std::chrono::seconds(120));
    // Requests from one client arrive in order: once another hand's read is
    // answered, the service has the INITIALIZE.
    const Reply probe = client_.hand(hand_address(3)).read(reg::position);
    EXPECT_TRUE(probe) << probe.message;
    return pending;
  }

  /// The call ends SERVICE_LOST and the hand goes OFFLINE, both saying why.
  void expect_death_seen(std::future<Reply>& pending) {
    ASSERT_EQ(pending.wait_for(kBeforeParticipantLease), std::future_status::ready)
        << "the call was not ended within the participant lease";
    const Reply lost = pending.get();
    EXPECT_EQ(lost.code, Code::service_lost) << lost.message;
    EXPECT_THAT(lost.message, HasSubstr("stopped asserting it lives"));
    EXPECT_THAT(lost.message, HasSubstr("may or may not have reached the hand"));
    const auto offline = offline_.wait(kBeforeParticipantLease);
    ASSERT_TRUE(offline) << "no OFFLINE event";
    EXPECT_THAT(*offline, HasSubstr("killed, frozen or cut off"));
    const auto status = client_.status(hand_address(2));
    ASSERT_TRUE(status);
    EXPECT_FALSE(status->online);
    EXPECT_TRUE(status->service_lost);
  }

  std::unique_ptr<RunningService> service_ =
      std::make_unique<RunningService>(sim_config(/*init_time_ms=*/600000));
  Client client_{client_options()};
  std::optional<Hand> hand_;
  OfflineLog offline_;
  Subscription subscription_;
};

TEST_F(FailoverTest, AKilledServiceIsSeenBeforeTheParticipantLease) {
  auto pending = command_in_flight();
  service_->process().process().send_signal(SIGKILL);
  expect_death_seen(pending);
}

TEST_F(FailoverTest, AFrozenServiceIsSeenAndServesAgainWhenItContinues) {
  auto pending = command_in_flight();
  Process& process = service_->process().process();
  process.send_signal(SIGSTOP);
  expect_death_seen(pending);
  EXPECT_FALSE(client_.service(test_service_name())->ready);
  process.send_signal(SIGCONT);
  // It asserts again: the same service, its hand online with its next status.
  EXPECT_TRUE(hand_->wait_until([](const HandStatus& s) { return s.online; }, kClientDeadline));
  const Reply read = hand_->read(reg::position);
  EXPECT_TRUE(read) << read.message;
}

TEST_F(FailoverTest, ACallInFlightToAFrozenServiceEndsWithItsHandsOfflineEvenIfItContinuesAtOnce) {
  // This client reads all it receives (nothing else runs in it), so the
  // lapse that takes the hand offline is the service's own silence and ends
  // the call with it (client/src/lapse_judge.hpp). The service continuing
  // right after the OFFLINE does not bring the call back: it was ended.
  auto pending = command_in_flight();
  Process& process = service_->process().process();
  process.send_signal(SIGSTOP);
  const auto offline = offline_.wait(kBeforeParticipantLease);
  process.send_signal(SIGCONT);
  ASSERT_TRUE(offline) << "no OFFLINE event";
  EXPECT_THAT(*offline, HasSubstr("killed, frozen or cut off"));
  ASSERT_EQ(pending.wait_for(kBeforeParticipantLease), std::future_status::ready)
      << "the call outlived its service's loss";
  const Reply lost = pending.get();
  EXPECT_EQ(lost.code, Code::service_lost) << lost.message;
  EXPECT_THAT(lost.message, HasSubstr("may or may not have reached the hand"));
  // The service asserts again: its hand comes back and serves.
  EXPECT_TRUE(hand_->wait_until([](const HandStatus& s) { return s.online; }, kClientDeadline));
  const Reply read = hand_->read(reg::position);
  EXPECT_TRUE(read) << read.message;
}

TEST_F(FailoverTest, DhctlEventsReportsAKilledServiceOffline) {
  Process events(DH3CTL_PATH, ctl_args({"events", hand_spec(2), "--count", "1"}),
                 Process::Stdin::dev_null);
  ASSERT_TRUE(events.wait_for_line("watching events", kClientDeadline));
  service_->process().process().send_signal(SIGKILL);
  const auto line = events.read_line(kBeforeParticipantLease);
  ASSERT_TRUE(line) << "dh3ctl events printed nothing within the participant lease";
  EXPECT_THAT(*line, HasSubstr("OFFLINE"));
  EXPECT_THAT(*line, HasSubstr("killed, frozen or cut off"));
}

/// An event as a watcher printed or got it: the hand ("svc/bus0/1") and the kind ("ONLINE").
struct Seen {
  std::string hand;
  std::string kind;
  std::uint64_t timestamp_ns = 0;  ///< 0: not known (a dh3ctl line)
};

/// Each hand had `kind` after its first OFFLINE.
bool each_had_after_offline(const std::vector<Seen>& seen, const std::vector<std::string>& hands,
                            std::string_view kind) {
  return std::all_of(hands.begin(), hands.end(), [&](const std::string& hand) {
    auto at = std::find_if(seen.begin(), seen.end(),
                           [&](const Seen& e) { return e.hand == hand && e.kind == "OFFLINE"; });
    return at != seen.end() && std::any_of(at, seen.end(), [&](const Seen& e) {
             return e.hand == hand && e.kind == kind;
           });
  });
}

/// Every event a subscription got, in order.
class EventRecord {
 public:
  void add(const HandEvent& event) {
    std::lock_guard lock(mutex_);
    seen_.push_back(
        Seen{event.hand.to_string(), std::string(to_string(event.kind)), event.timestamp_ns});
    changed_.notify_all();
  }
  /// The events once each of `hands` had `kind` after its OFFLINE, or at `timeout`.
  std::vector<Seen> wait_after_offline(const std::vector<std::string>& hands, std::string_view kind,
                                       std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return each_had_after_offline(seen_, hands, kind); });
    return seen_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Seen> seen_;
};

/// dh3ctl events' lines ("svc/bus0/1 ONLINE position ...") until each of
/// `hands` had `kind` after its OFFLINE, or at `timeout`.
std::vector<Seen> read_after_offline(Process& ctl, const std::vector<std::string>& hands,
                                     std::string_view kind, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::vector<Seen> seen;
  while (!each_had_after_offline(seen, hands, kind)) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    const auto line = ctl.read_line(std::max(left, std::chrono::milliseconds(0)));
    if (!line) break;
    const auto first = line->find(' ');
    const auto second = line->find(' ', first + 1);
    if (first == std::string::npos) continue;
    seen.push_back(Seen{line->substr(0, first), line->substr(first + 1, second - first - 1)});
  }
  return seen;
}

std::uint64_t wall_clock_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

/// For each hand: one ONLINE between its first OFFLINE and its INITIALIZED
/// (the service's events come in order: its own ONLINE, had it reached the
/// watcher, would have come before its INITIALIZED), at a real time if known.
void expect_offline_then_one_online(const std::vector<Seen>& seen,
                                    const std::vector<std::string>& hands, std::uint64_t after_ns,
                                    const std::string& watcher) {
  for (const std::string& hand : hands) {
    SCOPED_TRACE(watcher + ", " + hand);
    const auto of = [&](std::string_view kind) {
      return [&hand, kind](const Seen& e) { return e.hand == hand && e.kind == kind; };
    };
    const auto offline = std::find_if(seen.begin(), seen.end(), of("OFFLINE"));
    ASSERT_NE(offline, seen.end()) << "no OFFLINE";
    const auto initialized = std::find_if(offline, seen.end(), of("INITIALIZED"));
    ASSERT_NE(initialized, seen.end()) << "no INITIALIZED after the restart";
    EXPECT_EQ(std::count_if(offline, initialized, of("ONLINE")), 1)
        << "not one ONLINE between OFFLINE and INITIALIZED";
    const auto online = std::find_if(offline, initialized, of("ONLINE"));
    // dh3ctl's lines do not show the time.
    if (online == initialized || watcher == "dh3ctl") continue;
    EXPECT_GE(online->timestamp_ns, after_ns) << "ONLINE at time " << online->timestamp_ns;
    EXPECT_LE(online->timestamp_ns, wall_clock_ns());
  }
}

/// An events-only watcher of every hand (dh3ctl events, and a subscription of
/// the client library) sees each hand OFFLINE when the service goes (stopped
/// or killed) and ONLINE once when it is back: the restarted service's own
/// ONLINE goes out before the watchers' readers matched its new event writer.
class RestartTest : public FailoverTest, public ::testing::WithParamInterface<int> {};

TEST_P(RestartTest, AnEventsWatcherSeesEveryHandOfflineThenOnlineOnce) {
  const std::vector<std::string> hands = {hand_spec(1), hand_spec(2), hand_spec(3)};
  EventRecord record;
  auto every_hand = client_.subscribe([&record](const HandEvent& e) { record.add(e); });
  Process ctl(DH3CTL_PATH, ctl_args({"events"}), Process::Stdin::dev_null);
  ASSERT_TRUE(ctl.wait_for_line("watching events", kClientDeadline));
  const std::uint64_t before_ns = wall_clock_ns();

  const auto stopped = service_->process().stop(GetParam());
  EXPECT_EQ(stopped.has_value(), GetParam() == SIGTERM);
  record.wait_after_offline(hands, "OFFLINE", kClientDeadline);
  service_ = std::make_unique<RunningService>(sim_config());
  ASSERT_TRUE(service_->started());
  for (std::uint16_t id = 1; id <= 3; ++id) {
    const Reply init = client_.hand(hand_address(id)).initialize();
    EXPECT_TRUE(init) << init.message;
  }

  expect_offline_then_one_online(record.wait_after_offline(hands, "INITIALIZED", kClientDeadline),
                                 hands, before_ns, "client library");
  expect_offline_then_one_online(read_after_offline(ctl, hands, "INITIALIZED", kClientDeadline),
                                 hands, before_ns, "dh3ctl");
}

INSTANTIATE_TEST_SUITE_P(StoppedOrKilled, RestartTest, ::testing::Values(SIGTERM, SIGKILL),
                         [](const ::testing::TestParamInfo<int>& signal_sent) {
                           return std::string(signal_sent.param == SIGTERM ? "Stopped" : "Killed");
                         });

TEST_F(FailoverTest, ASecondServiceOfTheNameRefusesToStartAndIsNeverSeen) {
  const pid_t owner_pid = service_->process().process().pid();
  const TempFile config(sim_config());
  // Its stderr into the pipe: the error must name the owner's process.
  Process duplicate("/bin/sh",
                    {"-c", "exec " + std::string(DH3_SERVICE_PATH) + " --domain " +
                               std::to_string(test_domain()) + " --name " + test_service_name() +
                               " --config " + config.path() + " --log-level warn 2>&1"},
                    Process::Stdin::dev_null);
  ASSERT_TRUE(duplicate.started());
  const auto error = wait_for_text(duplicate, "already served", kClientDeadline);
  ASSERT_TRUE(error) << "the duplicate did not say why it refused";
  EXPECT_THAT(*error, HasSubstr("pid " + std::to_string(owner_pid)));
  EXPECT_THAT(*error, HasSubstr("on host '"));
  const auto status = duplicate.wait_exit(kClientDeadline);
  ASSERT_TRUE(status && WIFEXITED(*status));
  EXPECT_NE(WEXITSTATUS(*status), 0);

  // The owner serves on, and nothing of the duplicate reached the client.
  const Reply read = hand_->read(reg::position);
  EXPECT_TRUE(read) << read.message;
  EXPECT_TRUE(client_.service(test_service_name())->ready);
  EXPECT_EQ(client_.watch_traffic().not_owner, 0U);
  EXPECT_TRUE(client_.status(hand_address(2))->online);
}

TEST_F(FailoverTest, AStatusFromAParticipantThatDoesNotOwnTheNameIsIgnored) {
  // A participant of this domain that is not the service writes a status of
  // the service's hand 2: fingers at 77, offline, with a newer update_seq.
  contract::ParticipantOptions options;
  options.name = "spoofer";
  options.domain = test_domain();
  contract::SetupReport report;
  auto spoofer = contract::Participant::create(options, report);
  ASSERT_TRUE(spoofer) << spoofer.error();
  auto* writer = (*spoofer)->publisher().create_datawriter(
      (*spoofer)->topics().status, contract::writer_qos(contract::TopicRole::hand_status));
  ASSERT_NE(writer, nullptr);
  const auto before = client_.status(hand_address(2));
  ASSERT_TRUE(before);
  msg::HandStatus forged;
  forged.service(test_service_name());
  forged.bus("bus0");
  forged.can_id(2);
  forged.online(false);
  forged.initialized(true);
  forged.position(77);
  forged.update_seq(before->update_seq + 1000);

  // Written until the client counted it: the writer's match is not announced.
  const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
  while (client_.watch_traffic().not_owner == 0 && std::chrono::steady_clock::now() < deadline) {
    ASSERT_TRUE(writer->write(&forged));
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_GT(client_.watch_traffic().not_owner, 0U) << "the forged status never reached the client";
  const auto after = client_.status(hand_address(2));
  ASSERT_TRUE(after);
  EXPECT_TRUE(after->online);
  EXPECT_NE(after->position, 77);
  const Reply read = hand_->read(reg::position);
  EXPECT_TRUE(read) << read.message;
  (*spoofer)->publisher().delete_datawriter(writer);
}

}  // namespace
}  // namespace dh3::test
