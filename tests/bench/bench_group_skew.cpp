// Group skew: how far apart the frames of one group command are on the wire.
// N hands (2, 4, 8) on the simulated 500 kbps CAN line (bit timing and
// arbitration, 111 bits per frame), the scheduler on its own thread with the
// real clock and the document's 20 ms interval per hand, the hands polled as
// usual. Each round is one group MOVE; its skew is from the first member's
// position write taking the line to the last one's, as a bus monitor would
// time them. The floor is the line's own: (N-1) frame times + 0.2 ms. Also
// two buses of N/2 hands each: how far apart the two buses' first frames of
// one group are (the common instant). Prints figures; asserts nothing.
//
//   bench_group_skew [--rounds R] [--reply-delay-us US]

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <vector>

#include "dh3/hand/bus_scheduler.hpp"
#include "dh3/hand/group_release.hpp"
#include "dh3/protocol/codec.hpp"
#include "dh3/sim/sim_bus.hpp"

namespace {

using namespace std::chrono_literals;
using namespace dh3;

constexpr std::uint32_t kBitRate = 500'000;
constexpr std::uint32_t kBitsPerFrame = 111;

class QuietObserver final : public hand::HandObserver {
 public:
  void on_state(const hand::HandState&) override {}
  void on_event(const hand::HandEvent&) override {}
  void on_link(bus::LinkState) override {}
};

/// Position writes as they leave the line, per bus.
struct LineLog {
  std::mutex mutex;
  std::vector<std::pair<TimePoint, std::uint32_t>> position_writes;  ///< line start, bus

  void note(const bus::CanFrame& frame, TimePoint started, std::uint32_t bus) {
    const auto message = protocol::decode_payload(static_cast<std::uint8_t>(frame.id),
                                                  std::span(frame.data.data(), frame.length));
    if (!message || message->reg != protocol::reg::kPosition ||
        message->access != protocol::Access::write) {
      return;
    }
    std::lock_guard lock(mutex);
    position_writes.emplace_back(started, bus);
  }
  std::vector<std::pair<TimePoint, std::uint32_t>> take() {
    std::lock_guard lock(mutex);
    auto out = std::move(position_writes);
    position_writes.clear();
    return out;
  }
};

struct Bus {
  std::unique_ptr<hand::BusScheduler> scheduler;
  std::vector<std::uint8_t> ids;
};

Bus make_bus(std::uint32_t index, const std::vector<std::uint8_t>& ids, Duration reply_delay,
             LineLog& log, QuietObserver& observer) {
  std::vector<sim::SimHandOptions> hands;
  std::vector<hand::HandConfig> configs;
  for (std::uint8_t id : ids) {
    sim::SimHandOptions h;
    h.id = id;
    h.init_time = 100ms;
    h.position_speed = 1000.0;
    h.reply_delay = reply_delay;
    hands.push_back(h);
    configs.push_back(hand::HandConfig{id, {}});
  }
  sim::SimBusOptions options;
  options.bit_rate = kBitRate;
  options.bits_per_frame = kBitsPerFrame;
  options.on_line = [&log, index](const bus::CanFrame& frame, TimePoint started, TimePoint,
                                  bool request) {
    if (request) log.note(frame, started, index);
  };
  auto sim_bus =
      std::make_unique<sim::SimBus>("sim:bench", hands, SystemClock::instance(), options);
  Bus bus;
  bus.ids = ids;
  bus.scheduler = std::make_unique<hand::BusScheduler>(
      "bus" + std::to_string(index), std::move(sim_bus), configs, hand::SchedulerOptions{},
      SystemClock::instance(), observer);
  bus.scheduler->start();
  return bus;
}

/// One group command to every hand of `buses`; waits for every member.
bool run_group(std::vector<Bus>& buses, hand::Command command, Duration lead) {
  std::size_t members = 0;
  for (const Bus& bus : buses) members += bus.ids.size();
  command.group = std::make_shared<hand::GroupRelease>(members, lead, SteadyClock::now() + 5s);
  std::mutex mutex;
  std::condition_variable done;
  std::size_t remaining = members;
  bool all_ok = true;
  for (Bus& bus : buses) {
    for (std::uint8_t id : bus.ids) {
      bus.scheduler->submit(id, command, [&](const hand::CommandResult& r) {
        std::lock_guard lock(mutex);
        all_ok = all_ok && r.ok();
        if (--remaining == 0) done.notify_all();
      });
    }
  }
  std::unique_lock lock(mutex);
  done.wait_for(lock, 20s, [&] { return remaining == 0; });
  return remaining == 0 && all_ok;
}

double us(Duration d) {
  return std::chrono::duration<double, std::micro>(d).count();
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto index = static_cast<std::size_t>(p * static_cast<double>(values.size() - 1));
  return values[index];
}

/// N hands on `bus_count` buses; prints the skew figures of `rounds` groups.
void measure(int hands, int bus_count, int rounds, Duration reply_delay) {
  LineLog log;
  QuietObserver observer;
  std::vector<Bus> buses;
  const int per_bus = hands / bus_count;
  for (int b = 0; b < bus_count; ++b) {
    std::vector<std::uint8_t> ids;
    for (int i = 1; i <= per_bus; ++i) ids.push_back(static_cast<std::uint8_t>(i));
    buses.push_back(make_bus(static_cast<std::uint32_t>(b), ids, reply_delay, log, observer));
  }
  const Duration lead = bus_count > 1 ? 2ms : Duration{};
  std::this_thread::sleep_for(300ms);  // the hands come online
  hand::Command init;
  init.kind = hand::CommandKind::initialize;
  if (!run_group(buses, init, lead)) {
    std::printf("  %d hands on %d bus(es): initialization failed\n", hands, bus_count);
    return;
  }
  std::vector<double> skews;
  std::vector<double> across;
  for (int r = 0; r < rounds; ++r) {
    log.take();
    hand::Command move;
    move.kind = hand::CommandKind::move_to;
    move.value = r % 2 == 0 ? 30 : 70;
    if (!run_group(buses, move, lead)) continue;
    const auto writes = log.take();
    if (writes.size() != static_cast<std::size_t>(hands)) continue;
    std::vector<TimePoint> first(static_cast<std::size_t>(bus_count), TimePoint::max());
    std::vector<TimePoint> last(static_cast<std::size_t>(bus_count), TimePoint::min());
    for (const auto& [at, bus] : writes) {
      first[bus] = std::min(first[bus], at);
      last[bus] = std::max(last[bus], at);
    }
    for (int b = 0; b < bus_count; ++b) skews.push_back(us(last[b] - first[b]));
    if (bus_count > 1) {
      const auto [lo, hi] = std::minmax_element(first.begin(), first.end());
      across.push_back(us(*hi - *lo));
    }
  }
  const double frame_us = 1e6 * kBitsPerFrame / kBitRate;
  const double floor_us = (per_bus - 1) * frame_us + 200.0;
  std::printf("  %d hands, %d bus(es) of %d: skew per bus median %.0f us, p95 %.0f us, max %.0f us;"
              " floor %.0f us; %zu groups\n",
              hands, bus_count, per_bus, percentile(skews, 0.5), percentile(skews, 0.95),
              percentile(skews, 1.0), floor_us, skews.size() / static_cast<std::size_t>(bus_count));
  if (bus_count > 1) {
    std::printf("    first frames of the buses apart: median %.0f us, p95 %.0f us, max %.0f us\n",
                percentile(across, 0.5), percentile(across, 0.95), percentile(across, 1.0));
  }
  for (Bus& bus : buses) bus.scheduler->stop();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Group command skew on the simulated 500 kbps CAN line"};
  int rounds = 40;
  int reply_delay_us = 0;
  app.add_option("--rounds", rounds, "group commands per configuration");
  app.add_option("--reply-delay-us", reply_delay_us,
                 "how long a simulated hand takes to answer (default 0: at once)");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::warn);
  const Duration delay = std::chrono::microseconds(reply_delay_us);
  std::printf("group skew, 500 kbps simulated line, %u-bit frames (%.0f us each), hands reply "
              "after %d us:\n",
              kBitsPerFrame, 1e6 * kBitsPerFrame / kBitRate, reply_delay_us);
  for (int hands : {2, 4, 8}) measure(hands, 1, rounds, delay);
  measure(8, 2, rounds, delay);
  return 0;
}
