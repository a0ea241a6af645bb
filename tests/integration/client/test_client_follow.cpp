// A plant in small: two dh3-services on one domain. A client that follows
// one cell (ClientOptions::follow) is sent none of the other cell's statuses
// and events: it reads in its cell's partition, which the other cells' writers
// do not publish in, and the services filter on their side; a client that
// follows one bus gets that bus only; a malformed follow is refused. Any
// number of clients get only their own replies (the 32 filtered readers of
// Fast DDS's default are lifted), and a hand at rest is republished once per
// dds.status_refresh_ms while any change goes out at once.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "client_fixture.hpp"

namespace dh3::test {
namespace {

/// A sim bus named `bus` with hands `ids`, read every 50 ms at rest.
std::string sim_bus(const std::string& bus, const std::string& ids) {
  return "  - name: " + bus +
         "\n"
         "    spec: sim:" +
         ids +
         "\n"
         "    command_interval_ms: 2\n"
         "    poll_interval_moving_ms: 20\n"
         "    poll_interval_idle_ms: 50\n"
         "    sim: {reply_delay_ms: 1, position_speed: 400, init_time_ms: 50}\n";
}

/// dh3-service named `name` with `yaml` as its configuration.
struct NamedService {
  NamedService(const std::string& name, const std::string& yaml)
      : config(yaml), process({"--config", config.path(), "--log-level", "warn"}, name) {}
  TempFile config;
  ServiceProcess process;
};

ClientOptions following(const std::string& follow) {
  ClientOptions options = client_options();
  options.follow = follow;
  return options;
}

/// Counts the statuses and events a client's callbacks get, by service and bus.
class Seen {
 public:
  explicit Seen(Client& client)
      : statuses_(client.subscribe_status([this](const HandStatus& s) { add(s.address, true); })),
        events_(client.subscribe([this](const HandEvent& e) { add(e.hand, false); })) {}
  int statuses(const std::string& service, const std::string& bus = {}) const {
    return count(status_by_, service, bus);
  }
  int events(const std::string& service, const std::string& bus = {}) const {
    return count(event_by_, service, bus);
  }

 private:
  using Counts = std::map<std::pair<std::string, std::string>, int>;
  void add(const HandAddress& hand, bool status) {
    std::lock_guard lock(mutex_);
    ++(status ? status_by_ : event_by_)[{hand.service, hand.bus}];
  }
  int count(const Counts& by, const std::string& service, const std::string& bus) const {
    std::lock_guard lock(mutex_);
    int total = 0;
    for (const auto& [key, n] : by) {
      if (key.first == service && (bus.empty() || key.second == bus)) total += n;
    }
    return total;
  }
  mutable std::mutex mutex_;
  Counts status_by_;
  Counts event_by_;
  Subscription statuses_;
  Subscription events_;
};

/// Polls `done` every 20 ms until it holds or kClientDeadline passes.
bool eventually(const std::function<bool()>& done) {
  const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

/// Initializes and moves a hand: statuses and events (INITIALIZED, ARRIVED).
void exercise(Client& client, const HandAddress& hand) {
  Hand h = client.hand(hand);
  const Reply init = h.initialize();
  ASSERT_TRUE(init) << init.message;
  const Reply move = h.move_to(60);
  ASSERT_TRUE(move) << move.message;
}

TEST(ClientFollow, AClientFollowingOneCellIsSentNoneOfTheOtherCellsStatusesOrEvents) {
  const std::string a = test_service_name() + "a";
  const std::string b = test_service_name() + "b";
  NamedService cell_a(a, "buses:\n" + sim_bus("bus0", "1,2,3"));
  NamedService cell_b(b, "buses:\n" + sim_bus("bus0", "1,2,3"));
  ASSERT_TRUE(cell_a.process.started() && cell_b.process.started());
  Client follower(following(a));
  Client everything(client_options());
  ASSERT_TRUE(follower.connected()) << follower.error();
  ASSERT_TRUE(everything.connected()) << everything.error();
  Seen seen(follower);
  Seen seen_all(everything);
  ASSERT_TRUE(follower.wait_for_service(a, kClientDeadline));
  ASSERT_TRUE(everything.wait_for_service(b, kClientDeadline));
  ASSERT_TRUE(everything.wait_for_service(a, kClientDeadline));
  ASSERT_TRUE(follower.wait_for_statuses(kClientDeadline));
  // Cell b's writers publish in its own partition and the default one, the
  // follower reads in cell a's (dh3/contract/cell_partition.hpp): they never match it,
  // so not even the samples they kept from before reach it (with the follow
  // filter alone, each hand's last status and the service info did).
  exercise(everything, {b, "bus0", 2});  // the other cell works
  exercise(follower, {a, "bus0", 1});    // and its own
  ASSERT_TRUE(eventually([&] { return seen_all.events(b) >= 2 && seen.events(a) >= 2; }));

  EXPECT_EQ(seen.statuses(b), 0);
  EXPECT_EQ(seen.events(b), 0);
  EXPECT_GT(seen.statuses(a), 0);
  EXPECT_GT(seen_all.statuses(b), 0);
  // Nothing of cell b reached it, then or since.
  EXPECT_EQ(follower.watch_traffic().dropped_on_arrival, 0U);
  EXPECT_GT(follower.watch_traffic().events, 0U);
  // It knows only its cell.
  const auto services = follower.services();
  ASSERT_EQ(services.size(), 1U);
  EXPECT_EQ(services[0].name, a);
  for (const auto& status : follower.hands()) EXPECT_EQ(status.address.service, a);
  EXPECT_FALSE(follower.service(b));
}

TEST(ClientFollow, AClientFollowingOneBusGetsThatBusOnly) {
  const std::string name = test_service_name();
  NamedService cell(name, "buses:\n" + sim_bus("bus0", "1,2") + sim_bus("bus1", "3,4"));
  ASSERT_TRUE(cell.process.started());
  Client follower(following(name + "/bus1"));
  Client everything(client_options());
  ASSERT_TRUE(follower.connected()) << follower.error();
  Seen seen(follower);
  Seen seen_all(everything);
  ASSERT_TRUE(follower.wait_for_service(name, kClientDeadline));
  // Every hand of the bus it follows, none of the other.
  ASSERT_TRUE(follower.wait_for_statuses(kClientDeadline));
  std::set<std::uint16_t> ids;
  for (const auto& status : follower.hands()) ids.insert(status.address.can_id);
  EXPECT_EQ(ids, (std::set<std::uint16_t>{3, 4}));
  ASSERT_TRUE(everything.wait_for_service(name, kClientDeadline));

  exercise(everything, {name, "bus0", 1});
  exercise(follower, {name, "bus1", 3});
  ASSERT_TRUE(
      eventually([&] { return seen_all.events(name, "bus0") >= 2 && seen.events(name) >= 2; }));
  EXPECT_EQ(seen.statuses(name, "bus0"), 0);
  EXPECT_EQ(seen.events(name, "bus0"), 0);
  EXPECT_GT(seen.statuses(name, "bus1"), 0);
  // The service info is the service's: both buses listed.
  const auto info = follower.service(name);
  ASSERT_TRUE(info);
  EXPECT_EQ(info->buses.size(), 2U);
}

TEST(ClientFollow, AMalformedFollowIsRefusedSayingWhy) {
  for (const std::string bad : {"cell/bus0/3", "/bus0", "cell 1"}) {
    Client client(following(bad));
    EXPECT_FALSE(client.connected()) << bad;
    EXPECT_NE(client.error().find("cannot follow '" + bad + "'"), std::string::npos)
        << client.error();
    EXPECT_EQ(client.hand({"cell", "bus0", 1}).read(0x0602).code, Code::not_connected);
  }
  const Finished ctl = dh3ctl({"--follow", "cell/bus0/3", "list"});
  ASSERT_TRUE(ctl.exit_code);
  EXPECT_NE(*ctl.exit_code, 0);
}

TEST(ClientFollow, Dh3ctlFollowsTheCellItIsTold) {
  const std::string a = test_service_name() + "a";
  const std::string b = test_service_name() + "b";
  NamedService cell_a(a, "buses:\n" + sim_bus("bus0", "1"));
  NamedService cell_b(b, "buses:\n" + sim_bus("bus0", "2"));
  Client everything(client_options());
  ASSERT_TRUE(everything.wait_for_service(a, kClientDeadline));
  ASSERT_TRUE(everything.wait_for_service(b, kClientDeadline));
  const Finished listed = dh3ctl({"--follow", b, "list"});
  ASSERT_EQ(listed.exit_code, 0) << listed.text();
  EXPECT_NE(listed.text().find(b), std::string::npos) << listed.text();
  EXPECT_EQ(listed.text().find(a), std::string::npos) << listed.text();
}

TEST(ClientFollow, ThirtySixClientsEachGetOnlyTheirOwnReplies) {
  // Fast DDS's writers filter for 32 readers by default; the 33rd and later
  // were sent every reply. The contract's writers filter for any number.
  RunningService service(sim_config());
  ASSERT_TRUE(service.started());
  constexpr int kClients = 36;
  std::vector<std::unique_ptr<Client>> clients;
  for (int i = 0; i < kClients; ++i) {
    clients.push_back(std::make_unique<Client>(client_options()));
    ASSERT_TRUE(clients.back()->connected()) << clients.back()->error();
  }
  // Every client's reply reader known to the service before any reply is
  // written: none is sent replies kept from before it joined.
  for (auto& client : clients) {
    ASSERT_TRUE(client->wait_for_service(test_service_name(), kClientDeadline));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  // Every client's three reads at once: any answer is a reply (the
  // service's, e.g. BUSY when a hand's queue is full), not a timeout.
  std::vector<std::thread> threads;
  std::mutex mutex;
  std::vector<std::string> unanswered;
  for (auto& client : clients) {
    threads.emplace_back([&client, &mutex, &unanswered] {
      for (std::uint16_t id = 1; id <= 3; ++id) {
        const Reply reply = client->hand(hand_address(id)).read(0x0602);
        if (reply.code == Code::no_reply || reply.code == Code::timeout) {
          std::lock_guard lock(mutex);
          unanswered.push_back(reply.message);
        }
      }
    });
  }
  for (auto& thread : threads) thread.join();
  ASSERT_TRUE(unanswered.empty()) << unanswered.size() << " unanswered, e.g. " << unanswered[0];
  // The last replies' way to the others would be over by the time a client
  // receives its own; a moment more for stragglers.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  std::uint64_t foreign = 0;
  for (auto& client : clients) {
    const CommandTraffic traffic = client->command_traffic();
    EXPECT_EQ(traffic.own_replies, 3U);
    foreign += traffic.foreign_replies;
  }
  EXPECT_EQ(foreign, 0U) << "replies to other clients reached the clients";
}

TEST(ClientFollow, ANewClientIsSentNoReplyOfTheClientsBeforeIt) {
  // The service keeps its last replies (TRANSIENT_LOCAL, for other vendors'
  // clients); a dh3 client reads replies VOLATILE and gets none of them.
  RunningService service(sim_config());
  ASSERT_TRUE(service.started());
  {
    Client earlier(client_options());
    ASSERT_TRUE(earlier.wait_for_service(test_service_name(), kClientDeadline));
    for (std::uint16_t id = 1; id <= 3; ++id) {
      ASSERT_TRUE(earlier.hand(hand_address(id)).read(0x0602));
    }
  }
  Client later(client_options());
  ASSERT_TRUE(later.wait_for_service(test_service_name(), kClientDeadline));
  const Reply own = later.hand(hand_address(1)).read(0x0602);
  ASSERT_TRUE(own) << own.message;
  // The kept replies would have come as its reader matched, before its own.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(later.command_traffic().own_replies, 1U);
  EXPECT_EQ(later.command_traffic().foreign_replies, 0U);
}

TEST(ClientFollow, AHandAtRestIsRepublishedOncePerRefreshAndAChangeAtOnce) {
  const std::string slow = test_service_name() + "slow";
  const std::string every = test_service_name() + "every";
  // One refresh a minute: within this test a hand at rest is not republished
  // at all, so a change that arrives went out because it changed.
  NamedService refresh(slow, "dds: {status_refresh_ms: 60000}\nbuses:\n" + sim_bus("bus0", "1"));
  NamedService no_refresh(every, "dds: {status_refresh_ms: 0}\nbuses:\n" + sim_bus("bus0", "1"));
  // A watcher, and a commander apart: what the watcher sees came on the
  // status topic, not with a reply.
  Client client(client_options());
  Client commander(client_options());
  ASSERT_TRUE(client.wait_for_service(slow, kClientDeadline));
  ASSERT_TRUE(client.wait_for_service(every, kClientDeadline));
  ASSERT_TRUE(commander.wait_for_service(slow, kClientDeadline));
  const HandAddress slow_hand{slow, "bus0", 1};
  const HandAddress every_hand{every, "bus0", 1};
  ASSERT_TRUE(client.hand(slow_hand).wait_until(
      [](const HandStatus& s) { return s.online && s.read_at_ns != 0; }, kClientDeadline));
  ASSERT_TRUE(client.hand(every_hand)
                  .wait_until([](const HandStatus& s) { return s.online && s.read_at_ns != 0; },
                              kClientDeadline));
  Seen seen(client);
  // The statuses already here are delivered first; count from a mark on.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const int slow_before = seen.statuses(slow);
  const int every_before = seen.statuses(every);
  // Both read every 50 ms at rest: about 40 reads in 2 s.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const int slow_at_rest = seen.statuses(slow) - slow_before;
  const int every_at_rest = seen.statuses(every) - every_before;
  EXPECT_LE(slow_at_rest, 3) << "republished at rest more than once per refresh";
  EXPECT_GE(every_at_rest, 15) << "status_refresh_ms 0 republishes every idle read";
  // A change goes out at once, refresh or not: the move's statuses arrive.
  Hand hand = commander.hand(slow_hand);
  ASSERT_TRUE(hand.initialize());
  ASSERT_TRUE(hand.move_to(60));
  EXPECT_TRUE(client.hand(slow_hand).wait_until(
      [](const HandStatus& s) { return s.position == 60 && s.grip == GripState::arrived; },
      kClientDeadline));
  EXPECT_GE(seen.statuses(slow) - slow_before, slow_at_rest + 2);
}

}  // namespace
}  // namespace dh3::test
