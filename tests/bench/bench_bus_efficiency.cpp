// Bus efficiency: 1, 8, 32, 64 and 255 hands on the simulated bus modelling a
// 500 kbps CAN line (bit timing and arbitration), no command interval, status
// polling as fast as the scheduler may. Reports the frames per second carried
// against the line-rate limit (111 bits per frame unstuffed, 135 worst case),
// the spread of per-hand status rates (fairness), and what the scheduler costs
// in CPU per simulated second. Time is simulated (FakeClock), so the frame
// figures are exact for the model; the CPU figure is measured.
//
//   bench_bus_efficiency [--seconds S] [--json FILE]

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "dh3/hand/bus_scheduler.hpp"
#include "dh3/sim/sim_bus.hpp"

namespace {

using namespace std::chrono_literals;
using namespace dh3;

class CountingObserver final : public hand::HandObserver {
 public:
  void on_state(const hand::HandState&) override {}
  void on_event(const hand::HandEvent&) override {}
  void on_link(bus::LinkState) override {}
};

/// Counts frames per hand as they are sent.
class CountingBus final : public bus::Bus {
 public:
  explicit CountingBus(std::unique_ptr<bus::Bus> inner) : inner_(std::move(inner)) {}
  const std::string& spec() const override { return inner_->spec(); }
  Result<void, bus::BusError> send(const bus::CanFrame& frame) override {
    auto r = inner_->send(frame);
    if (r) ++sent_per_hand[frame.id];
    return r;
  }
  Result<void, bus::BusError> receive(std::vector<bus::CanFrame>& out, Duration t) override {
    const std::size_t before = out.size();
    auto r = inner_->receive(out, t);
    received += out.size() - before;
    return r;
  }
  void wake() override { inner_->wake(); }
  bus::LinkState link_state() const override { return inner_->link_state(); }
  std::uint32_t bit_rate() const override { return inner_->bit_rate(); }

  std::map<std::uint32_t, std::uint64_t> sent_per_hand;
  std::uint64_t received = 0;

 private:
  std::unique_ptr<bus::Bus> inner_;
};

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

struct Row {
  int hands = 0;
  double frames_per_s = 0;
  double line_limit_111 = 0;
  double line_limit_135 = 0;
  double min_rate = 0;
  double max_rate = 0;
  double cpu_ms_per_sim_s = 0;
  std::uint64_t timeouts = 0;
};

Row run(int hands, double seconds) {
  constexpr std::uint32_t kBitRate = 500'000;
  FakeClock clock;
  std::vector<sim::SimHandOptions> sim;
  std::vector<hand::HandConfig> configs;
  for (int id = 1; id <= hands; ++id) {
    sim::SimHandOptions o;
    o.id = static_cast<std::uint8_t>(id);
    sim.push_back(o);
    configs.push_back(hand::HandConfig{static_cast<std::uint8_t>(id), {}});
  }
  sim::SimBusOptions line;
  line.bit_rate = kBitRate;
  line.bits_per_frame = 111;
  line.tx_queue_length = 4;
  auto counting = std::make_unique<CountingBus>(
      std::make_unique<sim::SimBus>("sim:bench", std::move(sim), clock, line));
  CountingBus* bus = counting.get();
  hand::SchedulerOptions options;
  options.command_interval = 0ms;
  options.poll_interval_moving = 0ms;
  options.poll_interval_idle = 0ms;
  CountingObserver observer;
  hand::BusScheduler scheduler("bench", std::move(counting), configs, options, clock, observer);

  // Warm up (hands come online, first reads), then measure.
  for (int i = 0; i < 1000; ++i) {
    clock.advance(100us);
    scheduler.step();
  }
  const auto sent_before = bus->sent_per_hand;
  const std::uint64_t received_before = bus->received;
  const double cpu_before = cpu_seconds();
  const auto steps = static_cast<long>(seconds * 10'000);
  for (long i = 0; i < steps; ++i) {
    clock.advance(100us);
    scheduler.step();
  }
  const double cpu = cpu_seconds() - cpu_before;

  Row row;
  row.hands = hands;
  std::uint64_t sent = 0;
  row.min_rate = 1e18;
  for (int id = 1; id <= hands; ++id) {
    const auto it = sent_before.find(static_cast<std::uint32_t>(id));
    const std::uint64_t n = bus->sent_per_hand[static_cast<std::uint32_t>(id)] -
                            (it == sent_before.end() ? 0 : it->second);
    sent += n;
    row.min_rate = std::min(row.min_rate, static_cast<double>(n) / seconds);
    row.max_rate = std::max(row.max_rate, static_cast<double>(n) / seconds);
  }
  row.frames_per_s = static_cast<double>(sent + (bus->received - received_before)) / seconds;
  row.line_limit_111 = kBitRate / 111.0;
  row.line_limit_135 = kBitRate / 135.0;
  row.cpu_ms_per_sim_s = cpu * 1000.0 / seconds;
  row.timeouts = scheduler.counters().timeouts;
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Bus efficiency: 1 to 255 hands on a simulated 500 kbps CAN line"};
  double seconds = 5;
  std::string json_path;
  app.add_option("--seconds", seconds, "Simulated seconds per row")->capture_default_str();
  app.add_option("--json", json_path, "Also write the results as JSON to this file");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::warn);
  std::vector<Row> rows;
  for (int hands : {1, 8, 32, 64, 255}) rows.push_back(run(hands, seconds));

  std::printf("Bus efficiency: sim bus at 500 kbps, no command interval, %.0f s simulated\n",
              seconds);
  std::printf("%6s %12s %10s %10s %12s %12s %9s %10s %9s\n", "hands", "frames/s", "% of 111b",
              "% of 135b", "hand min/s", "hand max/s", "min/max", "cpu ms/s", "timeouts");
  for (const Row& r : rows) {
    std::printf("%6d %12.0f %9.1f%% %9.1f%% %12.1f %12.1f %8.1f%% %10.1f %9llu\n", r.hands,
                r.frames_per_s, 100 * r.frames_per_s / r.line_limit_111,
                100 * r.frames_per_s / r.line_limit_135, r.min_rate, r.max_rate,
                100 * r.min_rate / r.max_rate, r.cpu_ms_per_sim_s,
                static_cast<unsigned long long>(r.timeouts));
  }
  if (!json_path.empty()) {
    std::FILE* f = std::fopen(json_path.c_str(), "w");
    if (f == nullptr) {
      std::perror(json_path.c_str());
      return 1;
    }
    std::fprintf(f,
                 "{\"benchmark\":\"bus_efficiency\",\"bit_rate\":500000,\"seconds\":%g,\"rows\":[",
                 seconds);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      std::fprintf(f,
                   "%s{\"hands\":%d,\"frames_per_s\":%.1f,\"line_limit_111\":%.1f,"
                   "\"line_limit_135\":%.1f,\"hand_min_per_s\":%.2f,\"hand_max_per_s\":%.2f,"
                   "\"cpu_ms_per_sim_s\":%.2f,\"timeouts\":%llu}",
                   i == 0 ? "" : ",", r.hands, r.frames_per_s, r.line_limit_111, r.line_limit_135,
                   r.min_rate, r.max_rate, r.cpu_ms_per_sim_s,
                   static_cast<unsigned long long>(r.timeouts));
    }
    std::fprintf(f, "]}\n");
    std::fclose(f);
  }
  return 0;
}
