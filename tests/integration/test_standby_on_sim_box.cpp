// A standby beside a primary on dh3-sim's transfer box shared as a bus
// (--shared): the box gives every client every frame, and a StandbyWatch on it
// keeps the hands' state as the primary's scheduler knows it, sending nothing.

#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "dh3/app/standby_watch.hpp"
#include "dh3/bus/bus_spec.hpp"
#include "support/process.hpp"
#include "support/raw_tcp_client.hpp"

namespace dh3::app {
namespace {

using namespace std::chrono_literals;
constexpr auto kDeadline = 10s;
constexpr std::size_t kFrame = 14;

/// Waits for `done` to hold, checking every 10 ms; false after kDeadline.
template <typename Predicate>
bool eventually(Predicate done) {
  const auto until = std::chrono::steady_clock::now() + kDeadline;
  while (!done()) {
    if (std::chrono::steady_clock::now() >= until) return false;
    std::this_thread::sleep_for(10ms);  // polling, not a wait for time
  }
  return true;
}

hand::Command command(hand::CommandKind kind, std::int32_t value = 0) {
  hand::Command made;
  made.kind = kind;
  made.value = value;
  return made;
}

class NullObserver final : public hand::HandObserver {
 public:
  void on_state(const hand::HandState&) override {}
  void on_event(const hand::HandEvent&) override {}
  void on_link(bus::LinkState) override {}
};

class StandbyOnSimBox : public ::testing::Test {
 protected:
  void SetUp() override {
    sim_ = std::make_unique<test::Process>(
        DH3_SIM_PATH, std::vector<std::string>{"--listen", "127.0.0.1:0", "--hands", "1,2",
                                               "--init-time-ms", "100", "--speed", "500",
                                               "--shared", "--log-level", "warn"});
    ASSERT_TRUE(sim_->started()) << "cannot start " << DH3_SIM_PATH;
    const auto line = sim_->wait_for_line("listening ", kDeadline);
    ASSERT_TRUE(line.has_value()) << "dh3-sim did not say where it listens";
    address_ = line->substr(std::string("listening ").size());
    port_ = static_cast<std::uint16_t>(std::stoi(address_.substr(address_.rfind(':') + 1)));
  }

  std::unique_ptr<bus::Bus> open_box() {
    auto opened = bus::open_bus("tcp:" + address_, SystemClock::instance(), {});
    EXPECT_TRUE(opened.ok()) << opened.error();
    return opened ? std::move(*opened) : nullptr;
  }

  std::unique_ptr<test::Process> sim_;
  std::string address_;
  std::uint16_t port_ = 0;
};

TEST_F(StandbyOnSimBox, EveryClientOfASharedBoxReceivesEveryFrame) {
  test::RawTcpClient primary(port_);
  test::RawTcpClient standby(port_);
  ASSERT_TRUE(primary.connected() && standby.connected());
  // The standby's connection is accepted once a frame of its own is answered;
  // the primary, sharing the line, sees that exchange too.
  ASSERT_TRUE(standby.send_hex("FF FE FD FC 02 13 01 00 00 00 00 00 00 FB"));
  EXPECT_EQ(standby.read_hex(kFrame, kDeadline), "FF FE FD FC 02 13 01 00 00 00 02 01 04 FB");
  EXPECT_EQ(primary.read_hex(kFrame, kDeadline), "FF FE FD FC 02 13 01 00 00 00 00 00 00 FB");
  EXPECT_EQ(primary.read_hex(kFrame, kDeadline), "FF FE FD FC 02 13 01 00 00 00 02 01 04 FB");
  ASSERT_TRUE(primary.send_hex("FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB"));
  EXPECT_EQ(primary.read_hex(kFrame, kDeadline), "FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB");
  // The request, then its echo: in the order a node on a CAN bus sees them.
  EXPECT_EQ(standby.read_hex(kFrame, kDeadline), "FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB");
  EXPECT_EQ(standby.read_hex(kFrame, kDeadline), "FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB");
}

TEST_F(StandbyOnSimBox, TheWatchKnowsWhatThePrimaryKnowsAndSendsNothing) {
  NullObserver observer;
  hand::SchedulerOptions options;
  options.interval_margin = 2ms;
  const std::vector<hand::HandConfig> hands{{1, {}}, {2, {}}};
  hand::BusScheduler primary("box", open_box(), hands, options, SystemClock::instance(),
                             observer);
  dds::BusSetup watched;
  watched.name = "box";
  watched.bus = open_box();
  watched.hands = hands;
  watched.scheduler = options;
  std::vector<dds::BusSetup> setups;
  setups.push_back(std::move(watched));
  StandbyWatch watch(std::move(setups), 600ms, SystemClock::instance());
  watch.start();
  primary.start();

  const auto call = [&](std::uint8_t id, hand::Command command) {
    std::promise<hand::CommandResult> done;
    auto result = done.get_future();
    primary.submit(id, command, [&](const hand::CommandResult& r) { done.set_value(r); });
    EXPECT_EQ(result.wait_for(kDeadline), std::future_status::ready);
    const auto ended = result.get();
    EXPECT_TRUE(ended.ok()) << to_string(ended.error());
  };
  call(1, command(hand::CommandKind::initialize));
  call(1, command(hand::CommandKind::move_to, 30));
  call(2, command(hand::CommandKind::set_closing_force, 80));

  const auto observed = [&](std::uint8_t id) -> std::optional<hand::HandState> {
    const auto buses = watch.states();
    for (const auto& state : buses.at(0)) {
      if (state.can_id == id) return state;
    }
    return std::nullopt;
  };
  EXPECT_TRUE(eventually([&] {
    const auto one = observed(1);
    const auto two = observed(2);
    return one && two && one->initialized && one->position == 30 && !two->initialized &&
           two->closing_force == 80;
  })) << "the standby's view of the hands never matched the primary's commands";
  EXPECT_GT(watch.requests_seen(), 0u);
  EXPECT_FALSE(watch.fences_clear(SteadyClock::now()));  // the primary polls: fenced
  EXPECT_FALSE(watch.silent_at());

  primary.stop();  // the primary goes quiet on the bus
  const TimePoint stopped = SteadyClock::now();
  EXPECT_TRUE(eventually([&] { return watch.fences_clear(SteadyClock::now()); }));
  // Read silent after the quiet time: the word that confirms a lapse at once.
  EXPECT_TRUE(eventually([&] {
    const auto silent = watch.silent_at();
    return silent && *silent >= stopped + 600ms;
  }));
  const auto taken = watch.take_buses();
  ASSERT_EQ(taken.size(), 1u);
  // Promoted: the taken bus sends now, and the hand answers it.
  ASSERT_TRUE(taken[0].bus->send(bus::CanFrame{1, 8, {0x06, 0x02, 0, 0, 0, 0, 0, 0}}));
}

}  // namespace
}  // namespace dh3::app
