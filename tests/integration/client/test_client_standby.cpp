// A hot standby beside its active service on dh3-sim's shared transfer box
// (docs/hot-standby.md), as a client sees it: the standby serves nothing and
// sends nothing while the active service lives, and when that one is killed
// it takes the bus over with the hands as they were: not re-initialized, at
// the position they had. Deadlines are generous; nothing is timed.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <condition_variable>
#include <csignal>
#include <future>
#include <initializer_list>
#include <mutex>
#include <string_view>
#include <thread>
#include <vector>

#include "client_fixture.hpp"
#include "dh3/contract/participant.hpp"
#include "dh3/contract/participant_setup.hpp"
#include "dh3/contract/qos.hpp"
#include "dh3/registers.hpp"

namespace dh3::test {
namespace {

using ::testing::AnyOf;
using ::testing::HasSubstr;
using ::testing::Not;

/// Two hands on a box at `spec`, polled fast so a test is quick.
std::string box_config(const std::string& spec) {
  return "buses:\n"
         "  - name: bus0\n"
         "    spec: " +
         spec +
         "\n"
         "    poll_interval_moving_ms: 20\n"
         "    poll_interval_idle_ms: 50\n"
         "    hands:\n"
         "      - {id: 1}\n"
         "      - {id: 2}\n";
}

/// The kinds of events a hand's subscription got, in order.
class EventLog {
 public:
  void add(const HandEvent& event) {
    std::lock_guard lock(mutex_);
    kinds_.push_back(event.kind);
    messages_.push_back(event.message);
    changed_.notify_all();
  }
  [[nodiscard]] std::string message(std::size_t index) {
    std::lock_guard lock(mutex_);
    return index < messages_.size() ? messages_[index] : std::string{};
  }
  /// Waits for an event of `kind` after the first `from` events; its index.
  std::optional<std::size_t> wait(EventKind kind, std::size_t from) {
    std::unique_lock lock(mutex_);
    std::optional<std::size_t> found;
    changed_.wait_for(lock, kClientDeadline, [&] {
      for (std::size_t i = from; i < kinds_.size(); ++i) {
        if (kinds_[i] == kind) found = i;
        if (found) return true;
      }
      return false;
    });
    return found;
  }
  [[nodiscard]] std::vector<EventKind> since(std::size_t from) {
    std::lock_guard lock(mutex_);
    return {kinds_.begin() + static_cast<std::ptrdiff_t>(std::min(from, kinds_.size())),
            kinds_.end()};
  }
  [[nodiscard]] std::size_t size() {
    std::lock_guard lock(mutex_);
    return kinds_.size();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<EventKind> kinds_;
  std::vector<std::string> messages_;
};

/// dh3-service --role standby (or `role`) with its log on stdout, read by the test.
class StandbyProcess {
 public:
  explicit StandbyProcess(const std::string& config_path, const std::string& role = "standby")
      : process_("/bin/sh",
                 {"-c", "exec " + std::string(DH3_SERVICE_PATH) + " --domain " +
                            std::to_string(test_domain()) + " --name " + test_service_name() +
                            " --config " + config_path + " --role " + role + " 2>&1"},
                 Process::Stdin::dev_null) {}
  [[nodiscard]] pid_t pid() const { return process_.pid(); }
  /// SIGKILL, and waits until it is gone.
  void kill() {
    process_.send_signal(SIGKILL);
    EXPECT_TRUE(process_.wait_exit(kClientDeadline)) << "a killed service did not end";
  }

  /// Reads its log until a line holds `text` (echoing it); that line.
  std::optional<std::string> wait_for(std::string_view text) { return wait_for_any({text}); }
  /// Reads its log until a line holds one of `texts`; that line.
  std::optional<std::string> wait_for_any(std::initializer_list<std::string_view> texts) {
    const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      auto line = process_.read_line(std::max(left, std::chrono::milliseconds(0)));
      if (!line) return std::nullopt;
      std::fprintf(stderr, "standby: %s\n", line->c_str());
      log_.push_back(*line);
      for (const std::string_view text : texts) {
        if (line->find(text) != std::string::npos) return line;
      }
    }
  }
  /// SIGTERM; its exit code once its log is read to the end.
  std::optional<int> stop() {
    process_.send_signal(SIGTERM);
    while (auto line = process_.read_line(kClientDeadline)) {
      std::fprintf(stderr, "standby: %s\n", line->c_str());
      log_.push_back(*line);
    }
    const auto status = process_.wait_exit(kClientDeadline);
    if (!status || !WIFEXITED(*status)) return std::nullopt;
    return WEXITSTATUS(*status);
  }
  [[nodiscard]] std::string log() const {
    std::string all;
    for (const auto& line : log_) all += line + "\n";
    return all;
  }

 private:
  Process process_;
  std::vector<std::string> log_;
};

class StandbyTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_NE(sim_.port(), 0) << "dh3-sim did not say where it listens"; }

  /// The client finds hand 1 online, initializes it and moves it to 30.
  void drive_hand() {
    auto found = client_.wait_for_hand(test_service_name() + "/bus0/1", kClientDeadline);
    ASSERT_TRUE(found) << found.message();
    hand_.emplace(*found);
    subscription_ = hand_->subscribe([this](const HandEvent& e) { events_.add(e); });
    ASSERT_TRUE(hand_->wait_until([](const HandStatus& s) { return s.online; }));
    const Reply init = hand_->initialize();
    ASSERT_TRUE(init) << init.message;
    const Reply moved = hand_->move_to(30);
    ASSERT_TRUE(moved) << moved.message;
  }

  /// `member` says it took over, and serves the hand, online, at `position`.
  /// Called after the kill: the new owner's service info started later.
  void take_over_at(StandbyProcess& member, std::int32_t position) {
    const auto killed_ns =
        static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                       std::chrono::system_clock::now().time_since_epoch())
                                       .count());
    ASSERT_TRUE(member.wait_for("took over from")) << "the standby never took over";
    // A standby may serve before the client believes the lapse; a call made
    // meanwhile is the lost owner's (SERVICE_LOST), so the read waits until
    // the client takes the new owner's service info for the service's.
    const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
    for (;;) {
      const auto info = client_.service(test_service_name());
      if (info && info->started_ns > killed_ns) break;
      ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the client never saw the new owner";
      std::this_thread::sleep_for(std::chrono::milliseconds(10));  // polling the client's view
    }
    ASSERT_TRUE(hand_->wait_until([](const HandStatus& s) { return s.online; }, kClientDeadline))
        << "the hand never came back online";
    const Reply read = hand_->read(reg::position);
    ASSERT_TRUE(read) << read.message;
    EXPECT_EQ(read.value, position);
  }

  SimProcess sim_{{"--hands", "1,2", "--init-time-ms", "100", "--speed", "500", "--shared",
                   "--log-level", "warn"}};
  Client client_{client_options()};
  std::optional<Hand> hand_;
  EventLog events_;
  Subscription subscription_;
};

TEST_F(StandbyTest, TakesOverAKilledServiceWithTheHandsAsTheyWere) {
  auto primary = std::make_unique<RunningService>(box_config(sim_.bus_spec()));
  ASSERT_TRUE(primary->started());
  const TempFile config(box_config(sim_.bus_spec()));
  StandbyProcess standby(config.path());
  ASSERT_TRUE(standby.wait_for("is served by")) << "the standby never saw the active service";
  drive_hand();
  ASSERT_FALSE(HasFatalFailure());

  const std::size_t before_kill = events_.size();
  primary->process().process().send_signal(SIGKILL);
  // Written to the killed service: answered once, by nobody else.
  auto in_flight = hand_->read_async(reg::position);
  const auto offline = events_.wait(EventKind::offline, before_kill);
  ASSERT_TRUE(offline) << "the client never saw the killed service's hand offline";
  const auto took_over = standby.wait_for("took over from");
  ASSERT_TRUE(took_over) << "the standby never said it took over";
  // Its statuses flow again, from the standby: the hand is back.
  ASSERT_TRUE(hand_->wait_until([](const HandStatus& s) { return s.online; }, kClientDeadline))
      << "the hand never came back online";

  // The call in flight ends with the killed service's loss (this client read
  // all it received), or as soon as the standby serves if its claim came
  // first (or, written after the client saw the loss, the standby answers it).
  ASSERT_EQ(in_flight.wait_for(kClientDeadline), std::future_status::ready);
  const Reply ended = in_flight.get();
  if (!ended) {
    EXPECT_EQ(ended.code, Code::service_lost) << ended.message;
    EXPECT_THAT(ended.message,
                AnyOf(HasSubstr("stopped asserting it lives"), HasSubstr("is now served by")));
    EXPECT_THAT(ended.message, HasSubstr("may or may not have reached the hand"));
  } else {
    EXPECT_EQ(ended.value, 30);
  }

  // The next command, served by the standby: the hand is where it was.
  const Reply read = hand_->read(reg::position);
  ASSERT_TRUE(read) << read.message;
  EXPECT_EQ(read.value, 30);
  const auto status = hand_->status();
  ASSERT_TRUE(status);
  EXPECT_TRUE(status->online);
  EXPECT_TRUE(status->initialized);
  const Reply moved = hand_->move_to(50);
  EXPECT_TRUE(moved) << moved.message;
  // Initialized once, by the client, before the kill: never again.
  for (const EventKind kind : events_.since(before_kill)) EXPECT_NE(kind, EventKind::initialized);
  EXPECT_EQ(standby.stop(), 0);
}

// The leases the primary granted are the standby's once it took over: the
// holder still holds its lease (another client is DENIED, naming it) and
// renews it; and every hand's watcher is told who serves the cell now.
TEST_F(StandbyTest, ALeaseSurvivesATakeoverAndWatchersAreToldOfIt) {
  auto primary = std::make_unique<RunningService>(box_config(sim_.bus_spec()));
  ASSERT_TRUE(primary->started());
  const pid_t primary_pid = primary->process().process().pid();
  const TempFile config(box_config(sim_.bus_spec()));
  StandbyProcess standby(config.path());
  ASSERT_TRUE(standby.wait_for("is served by")) << "the standby never saw the active service";
  drive_hand();  // client A: hand 1 initialized, at 30, its events watched
  ASSERT_FALSE(HasFatalFailure());
  auto found_other = client_.wait_for_hand(test_service_name() + "/bus0/2", kClientDeadline);
  ASSERT_TRUE(found_other) << found_other.message();
  EventLog other_events;
  const Subscription other_watch =
      found_other->subscribe([&other_events](const HandEvent& e) { other_events.add(e); });

  const Reply leased = hand_->acquire_lease(std::chrono::seconds(60));
  ASSERT_TRUE(leased) << leased.message;
  const std::string holder = leased.lease_holder;
  ASSERT_FALSE(holder.empty());
  ClientOptions b_options = client_options();
  b_options.participant_name = "client-b";
  Client b(b_options);
  auto b_hand = b.wait_for_hand(test_service_name() + "/bus0/1", kClientDeadline);
  ASSERT_TRUE(b_hand) << b_hand.message();
  const Reply denied_before = b_hand->move_to(60);
  ASSERT_EQ(denied_before.code, Code::denied) << denied_before.message;

  const std::size_t before_kill = events_.size();
  const std::size_t other_before_kill = other_events.size();
  primary->process().process().send_signal(SIGKILL);
  ASSERT_TRUE(standby.wait_for("took over from")) << "the standby never took over";
  const auto taken_over = events_.wait(EventKind::taken_over, before_kill);
  ASSERT_TRUE(taken_over) << "hand 1's watcher was never told of the takeover";
  EXPECT_THAT(events_.message(*taken_over),
              HasSubstr("is now served by pid " + std::to_string(standby.pid())));
  EXPECT_THAT(events_.message(*taken_over),
              HasSubstr("took over from pid " + std::to_string(primary_pid)));
  EXPECT_TRUE(other_events.wait(EventKind::taken_over, other_before_kill))
      << "hand 2's watcher was never told of the takeover";
  ASSERT_TRUE(hand_->wait_until([](const HandStatus& s) { return s.online; }, kClientDeadline))
      << "the hand never came back online";

  // Served by the standby now: the lease is still A's.
  const Reply denied = b_hand->move_to(60);
  EXPECT_EQ(denied.code, Code::denied) << denied.message;
  EXPECT_EQ(denied.lease_holder, holder);
  EXPECT_THAT(denied.message, HasSubstr(holder));
  const Reply taken = b_hand->acquire_lease(std::chrono::seconds(5));
  EXPECT_EQ(taken.code, Code::denied) << taken.message;
  // A participant that writes A's client id into its requests is not A.
  DdsTestClient forger(test_domain(), "forger");
  ASSERT_TRUE(forger.wait_for_service(test_service_name()));
  auto forged =
      forger.request(DdsTestClient::hand(test_service_name(), "bus0", 1), msg::MOVE, 70);
  forged.client_id(client_.client_id());
  forged.request_seq(1'000'000);
  forger.send(forged, true);
  const auto forged_reply = forger.wait_reply(1'000'000, kDdsDeadline, client_.client_id());
  ASSERT_TRUE(forged_reply) << "the forged request was never answered";
  EXPECT_EQ(forged_reply->code(), msg::DENIED) << forged_reply->message();
  EXPECT_EQ(forged_reply->lease_holder(), holder);
  const Reply renewed = hand_->renew_lease(std::chrono::seconds(60));
  EXPECT_TRUE(renewed) << renewed.message;
  const Reply moved = hand_->move_to(50);
  EXPECT_TRUE(moved) << moved.message;
  const auto status = hand_->status();
  ASSERT_TRUE(status);
  EXPECT_EQ(status->lease_holder, holder);
  EXPECT_THAT(standby.log(), HasSubstr("carried over"));
  EXPECT_EQ(standby.stop(), 0);
}

TEST_F(StandbyTest, AStandbyWhosePrimaryLivesTakesNothingAndSendsNothing) {
  // The standby reaches the box through a proxy that records what it sends.
  RecordingProxy proxy(sim_.port());
  auto primary = std::make_unique<RunningService>(box_config(sim_.bus_spec()));
  ASSERT_TRUE(primary->started());
  const TempFile config(box_config(proxy.bus_spec()));
  StandbyProcess standby(config.path());
  ASSERT_TRUE(standby.wait_for("is served by")) << "the standby never saw the active service";
  drive_hand();
  ASSERT_FALSE(HasFatalFailure());
  for (int i = 0; i < 5; ++i) {
    const Reply moved = hand_->move_to(20 + 10 * i);
    ASSERT_TRUE(moved) << moved.message;
  }
  EXPECT_EQ(standby.stop(), 0);
  EXPECT_EQ(proxy.connections(), 1) << "the standby never connected to the box";
  EXPECT_TRUE(proxy.sent().empty())
      << "the standby sent frames: " << ::testing::PrintToString(frames_as_hex(proxy.sent()));
  EXPECT_THAT(standby.log(), Not(HasSubstr("took over")));
  // The active service served throughout.
  EXPECT_EQ(primary->process().stop(), 0);
}

// A standby makes the service's endpoints as it starts, so that a client
// has matched them long before a takeover: its calls go to the new owner as
// soon as the claim turns active, without waiting for endpoint discovery.
TEST_F(StandbyTest, AClientHasMatchedTheStandbysServiceEndpointsWhileThePrimaryLives) {
  auto primary = std::make_unique<RunningService>(box_config(sim_.bus_spec()));
  ASSERT_TRUE(primary->started());
  contract::ParticipantOptions options;
  options.name = "endpoint-observer";
  options.domain = test_domain();
  contract::SetupReport report;
  auto observer = contract::Participant::create(options, report);
  ASSERT_TRUE(observer) << observer.error();
  const contract::Topics& topics = (*observer)->topics();
  auto* requests = (*observer)->publisher().create_datawriter(
      topics.request, contract::writer_qos(contract::TopicRole::request));
  auto* replies = (*observer)->subscriber().create_datareader(
      topics.reply, contract::reader_qos(contract::TopicRole::reply));
  auto* events = (*observer)->subscriber().create_datareader(
      topics.event, contract::reader_qos(contract::TopicRole::hand_event));
  ASSERT_TRUE(requests != nullptr && replies != nullptr && events != nullptr);
  // The service's request reader, reply writer and event writer, and as many
  // of the standby's: what a client needs matched to send it calls.
  const auto matched = [&] {
    eprosima::fastdds::dds::PublicationMatchedStatus request_readers;
    eprosima::fastdds::dds::SubscriptionMatchedStatus reply_writers;
    eprosima::fastdds::dds::SubscriptionMatchedStatus event_writers;
    requests->get_publication_matched_status(request_readers);
    replies->get_subscription_matched_status(reply_writers);
    events->get_subscription_matched_status(event_writers);
    return std::min({request_readers.current_count, reply_writers.current_count,
                     event_writers.current_count});
  };
  const auto wait_for = [&](int count) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (matched() < count && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return matched();
  };
  ASSERT_EQ(wait_for(1), 1) << "the active service's endpoints never matched";

  const TempFile config(box_config(sim_.bus_spec()));
  StandbyProcess standby(config.path());
  ASSERT_TRUE(standby.wait_for("is served by")) << "the standby never saw the active service";
  EXPECT_EQ(wait_for(2), 2) << "the standby's service endpoints did not match while it stood by";
  EXPECT_THAT(standby.log(), Not(HasSubstr("took over")));
  EXPECT_EQ(standby.stop(), 0);
  EXPECT_EQ(primary->process().stop(), 0);
}

// An active service that DDS does not show the cell's serving one (here it
// is on another domain, as across a network partition) still finds the bus
// driven: it watches the bus before its first frame, refuses to start and
// sends nothing.
TEST_F(StandbyTest, AnActiveServiceFindingItsBusDrivenByAnotherRefusesAndSendsNothing) {
  auto primary = std::make_unique<RunningService>(box_config(sim_.bus_spec()));
  ASSERT_TRUE(primary->started());
  drive_hand();
  ASSERT_FALSE(HasFatalFailure());
  RecordingProxy proxy(sim_.port());
  const TempFile config(box_config(proxy.bus_spec()));
  // Outside test_domain()'s range: no test's service is there.
  constexpr int kOtherDomain = 230;
  const auto [code, output] =
      run_to_exit("--domain " + std::to_string(kOtherDomain) + " --name " + test_service_name() +
                  " --config " + config.path() + " --role active");
  EXPECT_EQ(code, 1) << output;
  EXPECT_THAT(output, HasSubstr("bus 'bus0' carries the requests of another service"));
  EXPECT_EQ(proxy.connections(), 1) << "the duplicate never connected to the box";
  EXPECT_TRUE(proxy.sent().empty())
      << "the duplicate sent frames: " << ::testing::PrintToString(frames_as_hex(proxy.sent()));
  // The cell's service serves on.
  const Reply read = hand_->read(reg::position);
  ASSERT_TRUE(read) << read.message;
  EXPECT_EQ(read.value, 30);
  EXPECT_EQ(primary->process().stop(), 0);
}

TEST_F(StandbyTest, AStandbyRefusesABusSimulatedInItsOwnProcess) {
  const auto [code, output] = run_to_exit("--domain " + std::to_string(test_domain()) + " --name " +
                                          test_service_name() + " --role standby --bus sim:1,2");
  EXPECT_EQ(code, 2) << output;
  EXPECT_THAT(output, HasSubstr("role: standby: bus 'bus0' (sim:1,2) is simulated"));
}

// Both members of the pair run alike (role auto): whichever finds the cell
// unserved serves it, the other stands by, and a member restarted after it
// was killed joins the one that took over as its standby.
TEST_F(StandbyTest, AnAutoPairTakesTurnsAndARestartedMemberStandsBy) {
  const TempFile config(box_config(sim_.bus_spec()));
  StandbyProcess first(config.path(), "auto");
  ASSERT_TRUE(first.wait_for("took the cell")) << "the first member never served the vacant cell";
  StandbyProcess second(config.path(), "auto");
  ASSERT_TRUE(second.wait_for("is served by")) << "the second member never stood by";
  drive_hand();
  ASSERT_FALSE(HasFatalFailure());
  const std::size_t before_kills = events_.size();

  first.kill();
  take_over_at(second, 30);
  ASSERT_FALSE(HasFatalFailure());

  // The killed member started again: through a proxy that records what it sends.
  RecordingProxy restarted_bus(sim_.port());
  const TempFile restarted_config(box_config(restarted_bus.bus_spec()));
  StandbyProcess restarted(restarted_config.path(), "auto");
  ASSERT_TRUE(restarted.wait_for("is served by")) << "the restarted member never stood by";
  const auto not_owner = client_.watch_traffic().not_owner;
  for (int i = 0; i < 4; ++i) {
    const Reply moved = hand_->move_to(40 + 10 * i);
    ASSERT_TRUE(moved) << moved.message;
  }
  EXPECT_EQ(restarted_bus.connections(), 1) << "the restarted member never connected to the box";
  EXPECT_TRUE(restarted_bus.sent().empty())
      << "the standing-by member sent frames: "
      << ::testing::PrintToString(frames_as_hex(restarted_bus.sent()));
  EXPECT_EQ(client_.watch_traffic().not_owner, not_owner)
      << "the client received statuses, events or replies of the standing-by member";

  second.kill();
  take_over_at(restarted, 70);
  ASSERT_FALSE(HasFatalFailure());
  const Reply moved = hand_->move_to(20);
  EXPECT_TRUE(moved) << moved.message;
  EXPECT_FALSE(restarted_bus.sent().empty()) << "the member that took over drives the bus";
  for (const EventKind kind : events_.since(before_kills)) EXPECT_NE(kind, EventKind::initialized);
  EXPECT_EQ(restarted.stop(), 0);
}

TEST_F(StandbyTest, OfTwoAutoMembersStartedTogetherOneServesAndTheOtherStandsBy) {
  RecordingProxy bus_a(sim_.port());
  RecordingProxy bus_b(sim_.port());
  const TempFile config_a(box_config(bus_a.bus_spec()));
  const TempFile config_b(box_config(bus_b.bus_spec()));
  StandbyProcess a(config_a.path(), "auto");
  StandbyProcess b(config_b.path(), "auto");
  const auto a_decided = a.wait_for_any({"took the cell", "is served by"});
  const auto b_decided = b.wait_for_any({"took the cell", "is served by"});
  ASSERT_TRUE(a_decided && b_decided) << "a member never decided";
  const bool a_serves = a_decided->find("took the cell") != std::string::npos;
  const bool b_serves = b_decided->find("took the cell") != std::string::npos;
  ASSERT_NE(a_serves, b_serves) << "exactly one member takes the cell";
  drive_hand();
  ASSERT_FALSE(HasFatalFailure());
  RecordingProxy& standing_by = a_serves ? bus_b : bus_a;
  EXPECT_TRUE(standing_by.sent().empty())
      << "the member standing by sent frames: "
      << ::testing::PrintToString(frames_as_hex(standing_by.sent()));
  EXPECT_FALSE((a_serves ? bus_a : bus_b).sent().empty()) << "the serving member drives the bus";
  EXPECT_EQ(a.stop(), 0);
  EXPECT_EQ(b.stop(), 0);
}

TEST_F(StandbyTest, AnActiveDuplicateOfAServingAutoMemberRefusesNamingIt) {
  const TempFile config(box_config(sim_.bus_spec()));
  StandbyProcess member(config.path(), "auto");
  ASSERT_TRUE(member.wait_for("took the cell")) << "the member never served the vacant cell";
  // The cell in use, as a copied configuration on a second PC would find it.
  drive_hand();
  ASSERT_FALSE(HasFatalFailure());
  const auto [code, output] =
      run_to_exit("--domain " + std::to_string(test_domain()) + " --name " + test_service_name() +
                  " --config " + config.path() + " --role active --log-level debug");
  EXPECT_EQ(code, 1) << output;
  EXPECT_THAT(output, HasSubstr("is already served on this domain by pid " +
                                std::to_string(member.pid()) + " on host '"));
  // The member serves on.
  const Reply read = hand_->read(reg::position);
  ASSERT_TRUE(read) << read.message;
  EXPECT_EQ(read.value, 30);
  EXPECT_EQ(member.stop(), 0);
}

}  // namespace
}  // namespace dh3::test
