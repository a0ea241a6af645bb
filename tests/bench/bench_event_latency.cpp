// Event latency: how long after a simulated hand's change (its object slips
// out, its fingers touch the object, they arrive) a client process hears of
// it: DROPPED, GRASPED, ARRIVED. The simulator knows the moment of the change
// (SimHand::grip_status_since, dh3-sim's `state ID`), on the steady clock,
// which is system-wide on Linux, so a client process can compare.
//
// Scenarios (dh3's Service runs in this process, the client is a child process
// started from this same program, --role client, printing each event with the
// steady time it arrived):
//   1 hand    dh3-sim over TCP (a transfer box), hand 2 with an object at 40
//   32 hands  the simulated CAN line at 500 kbps, every hand holding an object;
//             one hand at a time drops, is released and grasps again
// Each cycle: grasp (until GRASPED), wait 0.2-0.8 s, drop, release to 100
// (until ARRIVED). Each event's p50 and p99 are printed next to the floor: the
// hand's frame spacing (command interval + margin), since dh3 hears of a change
// only by reading a status and may read one per spacing.
// The service's own latency histograms (its metrics endpoint, started here on
// loopback and scraped before and after the cycles) are set against what the
// benchmark measured itself: a command's time from request to reply, as the
// client saw it, and the histogram's estimate of the same quantile.
// Then the bus load each state costs a hand (simulated time).

#include <spdlog/spdlog.h>

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "dh3/app/bus_setup.hpp"
#include "dh3/app/config.hpp"
#include "dh3/client.hpp"
#include "dh3/registers.hpp"
#include "dh3/dds/service.hpp"
#include "dh3/hand/bus_scheduler.hpp"
#include "dh3/metrics/metrics_exporter.hpp"
#include "dh3/sim/sim_bus.hpp"
#include "support/metrics_scrape.hpp"

namespace {

using namespace std::chrono_literals;
using dh3::bench::BenchClock;

std::int64_t steady_ns(BenchClock::time_point t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

// ---------------------------------------------------------------------------
// The client process: every event, with the steady time it arrived.

int run_client(const dh3::bench::CommonOptions& common) {
  dh3::ClientOptions options;
  options.domain = common.domain;
  dh3::Client client(options);
  if (!client.connected()) return 1;
  std::mutex out_mutex;
  auto subscription = client.subscribe([&](const dh3::HandEvent& e) {
    const std::int64_t now = steady_ns(BenchClock::now());
    std::lock_guard lock(out_mutex);
    std::printf("ev %u %s %lld\n", static_cast<unsigned>(e.hand.can_id),
                std::string(dh3::to_string(e.kind)).c_str(), static_cast<long long>(now));
    std::fflush(stdout);
  });
  if (!client.wait_for_service(common.service, 30s)) return 1;
  {
    std::lock_guard lock(out_mutex);
    std::printf("ready\n");
    std::fflush(stdout);
  }
  std::string line;
  while (std::getline(std::cin, line)) {
  }  // until the benchmark closes our stdin
  return 0;
}

/// The client child's events, read on a thread of their own.
class EventLog {
 public:
  explicit EventLog(dh3::test::Process& child) : child_(child) {
    reader_ = std::thread([this] { read(); });
  }
  ~EventLog() {
    stop_ = true;
    reader_.join();
  }
  bool wait_ready(std::chrono::seconds limit) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, limit, [&] { return ready_; });
  }
  /// The first `kind` event of hand `id` that arrived after `after`, waiting up to `limit`.
  std::optional<std::int64_t> wait_for(unsigned id, const std::string& kind, std::int64_t after,
                                       std::chrono::seconds limit) {
    std::unique_lock lock(mutex_);
    std::optional<std::int64_t> found;
    changed_.wait_for(lock, limit, [&] {
      for (const auto& [when, event_id, event_kind] : events_) {
        if (event_id == id && event_kind == kind && when > after) {
          found = when;
          return true;
        }
      }
      return false;
    });
    return found;
  }

 private:
  void read() {
    while (!stop_) {
      auto line = child_.read_line(200ms);
      if (!line) continue;
      std::istringstream in(*line);
      std::string word;
      in >> word;
      std::lock_guard lock(mutex_);
      if (word == "ready") {
        ready_ = true;
      } else if (word == "ev") {
        unsigned id = 0;
        std::string kind;
        long long when = 0;
        in >> id >> kind >> when;
        events_.push_back({when, id, kind});
      }
      changed_.notify_all();
    }
  }
  struct Seen {
    std::int64_t when;
    unsigned id;
    std::string kind;
  };
  dh3::test::Process& child_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Seen> events_;
  bool ready_ = false;
  std::atomic<bool> stop_{false};
  std::thread reader_;
};

// ---------------------------------------------------------------------------
// The simulated hands, either in dh3-sim (TCP) or on the in-process sim bus.

class Sim {
 public:
  virtual ~Sim() = default;
  virtual void place_object(unsigned id, int position) = 0;
  /// Drops hand `id`'s object; returns the moment (steady ns).
  virtual std::int64_t drop(unsigned id) = 0;
  /// When hand `id`'s grip status took its current value (steady ns).
  virtual std::int64_t grip_since(unsigned id) = 0;
};

class TcpSim final : public Sim {
 public:
  explicit TcpSim(dh3::test::Process& sim) : sim_(sim) {}
  void place_object(unsigned id, int position) override {
    command("object " + std::to_string(id) + " " + std::to_string(position));
  }
  std::int64_t drop(unsigned id) override {
    command("drop " + std::to_string(id));
    return grip_since(id);  // the fingers take 200 ms to close after it
  }
  std::int64_t grip_since(unsigned id) override {
    const std::string answer = command("state " + std::to_string(id));
    const auto at = answer.find("grip_status_since_ns=");
    return at == std::string::npos ? 0 : std::stoll(answer.substr(at + 21));
  }

 private:
  std::string command(const std::string& line) {
    sim_.write_line(line);
    return sim_.wait_for_line("ok", 5s).value_or("");
  }
  dh3::test::Process& sim_;
};

class InProcessSim final : public Sim {
 public:
  explicit InProcessSim(dh3::sim::SimBus& bus) : bus_(bus) {}
  void place_object(unsigned id, int position) override {
    bus_.with_hand(static_cast<std::uint8_t>(id),
                   [&](dh3::sim::SimHand& hand) { hand.place_object(position); });
  }
  std::int64_t drop(unsigned id) override {
    std::int64_t at = 0;
    bus_.with_hand(static_cast<std::uint8_t>(id), [&](dh3::sim::SimHand& hand) {
      hand.drop_object();
      at = steady_ns(hand.grip_status_since());
    });
    return at;
  }
  std::int64_t grip_since(unsigned id) override {
    std::int64_t at = 0;
    bus_.with_hand(static_cast<std::uint8_t>(id),
                   [&](dh3::sim::SimHand& hand) { at = steady_ns(hand.grip_status_since()); });
    return at;
  }

 private:
  dh3::sim::SimBus& bus_;
};

// ---------------------------------------------------------------------------
// One scenario.

/// One histogram of the scrape: (upper bound in seconds, cumulative count),
/// +Inf last, as the text has them.
using Buckets = std::vector<std::pair<double, double>>;

/// `name`'s buckets for bus `bus` in a scrape's text.
Buckets buckets_of(const std::string& text, const std::string& name, const std::string& bus) {
  const std::string prefix = name + "_bucket{bus=\"" + bus + "\",le=\"";
  Buckets out;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(prefix, 0) != 0) continue;
    const std::size_t end = line.find('"', prefix.size());
    const std::string le = line.substr(prefix.size(), end - prefix.size());
    const double bound = le == "+Inf" ? INFINITY : std::stod(le);
    out.emplace_back(bound, std::stod(line.substr(line.find(' ', end) + 1)));
  }
  return out;
}

/// after - before, bucket by bucket: what the cycles alone added.
Buckets minus(Buckets after, const Buckets& before) {
  for (std::size_t i = 0; i < after.size() && i < before.size(); ++i) {
    after[i].second -= before[i].second;
  }
  return after;
}

/// Prometheus' histogram_quantile(q, ...) on one series, in ms; and the width
/// of the bucket the estimate fell in (the histogram's resolution there).
struct Estimate {
  double ms = NAN;
  double bucket_ms = NAN;
};
Estimate histogram_quantile(double q, const Buckets& buckets) {
  if (buckets.empty() || buckets.back().second <= 0) return {};
  const double rank = q * buckets.back().second;
  double lower = 0.0;
  double below = 0.0;
  for (const auto& [bound, cumulative] : buckets) {
    if (cumulative >= rank) {
      if (std::isinf(bound)) return {lower * 1e3, NAN};  // as Prometheus: the last finite bound
      const double within = cumulative > below ? (rank - below) / (cumulative - below) : 1.0;
      return {(lower + (bound - lower) * within) * 1e3, (bound - lower) * 1e3};
    }
    lower = bound;
    below = cumulative;
  }
  return {};
}

/// What one scenario measured.
struct Latencies {
  std::vector<double> drop, grasp, arrival;  // ms
  int lost = 0;                              // events not seen in time
  double floor_ms = 0.0;                     // the hand's frame spacing
  std::vector<double> command_ms;  // release and grasp, request to reply, as the client saw
  std::vector<double> read_ms;     // grip-status reads after the cycles, the same
  /// What the service's histograms gained over the cycles (its own scrape),
  /// and command_to_reply over the reads alone.
  Buckets command_to_reply, command_to_frame, frame_to_reply, sample_age, read_to_reply;
};

/// The rows of the latency table, for --json.
std::string json_rows;

void print_row(const char* scenario, const char* kind, std::vector<double>& ms, double floor_ms) {
  const auto p = dh3::bench::percentiles(ms);
  std::printf("| %-32s | %-8s | %5zu | %7.1f | %7.1f | %7.1f | %5.1f | %5.2fx | %5.2fx |\n",
              scenario, kind, p.count, p.p50, p.p99, p.max, floor_ms, p.p50 / floor_ms,
              p.p99 / floor_ms);
  char row[500];
  std::snprintf(row, sizeof row,
                "%s{\"scenario\":\"%s\",\"event\":\"%s\",\"count\":%zu,\"p50_ms\":%.2f,"
                "\"p99_ms\":%.2f,\"max_ms\":%.2f,\"floor_ms\":%.2f,\"p99_ratio\":%.3f}",
                json_rows.empty() ? "" : ",", scenario, kind, p.count, p.p50, p.p99, p.max,
                floor_ms, p.p99 / floor_ms);
  json_rows += row;
}

void print_rows(const char* scenario, Latencies& l) {
  print_row(scenario, "DROPPED", l.drop, l.floor_ms);
  print_row(scenario, "GRASPED", l.grasp, l.floor_ms);
  print_row(scenario, "ARRIVED", l.arrival, l.floor_ms);
}

/// A client-side figure against the histogram's estimate of the same quantile.
void print_agreement(const char* scenario, const char* what, std::vector<double>& ms,
                     const Buckets& buckets) {
  const auto client = dh3::bench::percentiles(ms);
  for (const double q : {0.50, 0.99}) {
    const Estimate estimate = histogram_quantile(q, buckets);
    const double seen = q == 0.50 ? client.p50 : client.p99;
    const bool agree = std::abs(seen - estimate.ms) <= estimate.bucket_ms;
    std::printf("| %-32s | %-26s p%-2.0f | %5zu | %7.1f | %7.1f | %6.1f | %-5s |\n", scenario, what,
                q * 100, client.count, seen, estimate.ms, estimate.bucket_ms, agree ? "yes" : "NO");
  }
}

/// The service's histograms against the client's own figures.
void print_histograms(const char* scenario, Latencies& l) {
  print_agreement(scenario, "read: request -> reply", l.read_ms, l.read_to_reply);
  print_agreement(scenario, "release, grasp: req.->reply", l.command_ms, l.command_to_reply);
  const auto show = [&](const char* what, const Buckets& b) {
    std::printf("| %-32s | %-30s | %5.0f |   p50 %7.1f   p99 %7.1f (histogram only) |\n", scenario,
                what, b.empty() ? 0.0 : b.back().second, histogram_quantile(0.50, b).ms,
                histogram_quantile(0.99, b).ms);
  };
  show("command request -> first frame", l.command_to_frame);
  show("frame -> reply", l.frame_to_reply);
  show("status sample age at publish", l.sample_age);
}

/// The service's latency histograms for `bus`, as scraped from `port`.
std::map<std::string, Buckets> scrape_latency(std::uint16_t port, const std::string& bus) {
  std::map<std::string, Buckets> out;
  const auto text = dh3::test::scrape_metrics(port);
  if (!text) return out;
  for (const char* name : {"command_to_reply", "command_to_frame", "frame_to_reply"}) {
    out[name] = buckets_of(*text, std::string("dh3_bus_") + name + "_seconds", bus);
  }
  out["sample_age"] = buckets_of(*text, "dh3_bus_status_sample_age_seconds", bus);
  return out;
}

std::optional<Latencies> run_scenario(const std::string& config_yaml, int domain,
                                      const std::vector<unsigned>& ids, int cycles,
                                      dh3::test::Process* tcp_sim) {
  auto config = dh3::app::parse_config(config_yaml, "bench");
  if (!config) {
    std::fprintf(stderr, "%s\n", config.error().message.c_str());
    return std::nullopt;
  }
  dh3::SystemClock clock;
  auto setups = dh3::app::open_buses(*config, clock);
  if (!setups) {
    std::fprintf(stderr, "%s\n", setups.error().c_str());
    return std::nullopt;
  }
  const std::string bus_name = setups->front().name;
  const auto spacing = setups->front().scheduler.frame_spacing();
  std::unique_ptr<Sim> sim;
  if (tcp_sim != nullptr) {
    sim = std::make_unique<TcpSim>(*tcp_sim);
  } else {
    auto* sim_bus = dynamic_cast<dh3::sim::SimBus*>(setups->front().bus.get());
    if (sim_bus == nullptr) return std::nullopt;
    sim = std::make_unique<InProcessSim>(*sim_bus);
  }
  dh3::dds::ServiceOptions options;
  options.name = "latency";
  options.participant.domain = domain;
  auto service = dh3::dds::Service::create(options, std::move(*setups), clock);
  if (!service || !(*service)->start()) {
    std::fprintf(stderr, "the service did not start\n");
    return std::nullopt;
  }
  auto exporter = dh3::metrics::Exporter::start(
      "127.0.0.1:0", [&figures = **service] { return figures.metrics(); });
  if (!exporter) {
    std::fprintf(stderr, "metrics: %s\n", exporter.error().c_str());
    return std::nullopt;
  }
  const auto port = static_cast<std::uint16_t>(
      std::stoi((*exporter)->address().substr((*exporter)->address().rfind(':') + 1)));
  dh3::test::Process child(
      dh3::bench::self_path(),
      {"--role", "client", "--domain", std::to_string(domain), "--service", options.name});
  EventLog log(child);
  dh3::ClientOptions client_options;
  client_options.domain = domain;
  dh3::Client client(client_options);
  if (!log.wait_ready(30s) || !client.wait_for_service(options.name, 30s)) {
    std::fprintf(stderr, "the client did not find the service\n");
    return std::nullopt;
  }
  std::map<unsigned, dh3::Hand> hands;
  for (unsigned id : ids) {
    hands.emplace(id, client.hand({options.name, bus_name, static_cast<std::uint16_t>(id)}));
  }
  for (auto& [id, hand] : hands) {
    if (auto r = hand.initialize(20s); !r.ok()) {
      std::fprintf(stderr, "hand %u: initialize: %s\n", id, r.message.c_str());
      return std::nullopt;
    }
  }
  // Every hand holds its object.
  for (auto& [id, hand] : hands) {
    sim->place_object(id, 40);
    if (auto r = hand.grasp(50, 10s); !r.ok() || r.grasp != dh3::GraspOutcome::grasped) {
      std::fprintf(stderr, "hand %u: first grasp failed: %s\n", id, r.message.c_str());
      return std::nullopt;
    }
  }
  std::this_thread::sleep_for(1s);
  Latencies out;
  out.floor_ms = std::chrono::duration<double, std::milli>(spacing).count();
  const auto before = scrape_latency(port, bus_name);
  if (before.empty()) {
    std::fprintf(stderr, "the service's metrics did not answer\n");
    return std::nullopt;
  }
  const auto timed = [&](auto call) {
    const auto start = BenchClock::now();
    auto result = call();
    out.command_ms.push_back(
        std::chrono::duration<double, std::milli>(BenchClock::now() - start).count());
    return result;
  };
  std::mt19937 random(17);
  std::uniform_int_distribution<int> hold_ms(200, 800);
  std::uniform_int_distribution<std::size_t> pick(0, ids.size() - 1);
  const auto ms_between = [](std::int64_t from, std::int64_t to) {
    return static_cast<double>(to - from) / 1e6;
  };
  for (int cycle = 0; cycle < cycles; ++cycle) {
    const unsigned id = ids[pick(random)];
    dh3::Hand& hand = hands.at(id);
    std::this_thread::sleep_for(std::chrono::milliseconds(hold_ms(random)));
    // Drop.
    const std::int64_t dropped_at = sim->drop(id);
    if (auto seen = log.wait_for(id, "DROPPED", dropped_at, 5s)) {
      out.drop.push_back(ms_between(dropped_at, *seen));
    } else {
      ++out.lost;
    }
    // Release to 100: ARRIVED.
    if (auto r = timed([&] { return hand.release(100, 10s); }); !r.ok()) {
      std::fprintf(stderr, "hand %u: release: %s\n", id, r.message.c_str());
      ++out.lost;
      continue;
    }
    const std::int64_t arrived_at = sim->grip_since(id);
    if (auto seen = log.wait_for(id, "ARRIVED", arrived_at, 5s)) {
      out.arrival.push_back(ms_between(arrived_at, *seen));
    } else {
      ++out.lost;
    }
    // Grasp again: GRASPED.
    sim->place_object(id, 40);
    if (auto r = timed([&] { return hand.grasp(50, 10s); });
        !r.ok() || r.grasp != dh3::GraspOutcome::grasped) {
      std::fprintf(stderr, "hand %u: grasp: %s\n", id, r.message.c_str());
      ++out.lost;
      continue;
    }
    const std::int64_t caught_at = sim->grip_since(id);
    if (auto seen = log.wait_for(id, "GRASPED", caught_at, 5s)) {
      out.grasp.push_back(ms_between(caught_at, *seen));
    } else {
      ++out.lost;
    }
  }
  auto after = scrape_latency(port, bus_name);
  out.command_to_reply = minus(after["command_to_reply"], before.at("command_to_reply"));
  out.command_to_frame = minus(after["command_to_frame"], before.at("command_to_frame"));
  out.frame_to_reply = minus(after["frame_to_reply"], before.at("frame_to_reply"));
  out.sample_age = minus(after["sample_age"], before.at("sample_age"));
  // Commands of one frame, at random moments: what a command's wait for the
  // hand's turn and its reply cost, in the histograms' 1-100 ms range.
  std::uniform_int_distribution<int> pause_ms(0, 40);
  for (int i = 0; i < 2 * cycles; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(pause_ms(random)));
    dh3::Hand& hand = hands.at(ids[pick(random)]);
    const auto start = BenchClock::now();
    if (auto r = hand.read(dh3::reg::grip_status, 5s); !r.ok()) {
      std::fprintf(stderr, "read: %s\n", r.message.c_str());
      continue;
    }
    out.read_ms.push_back(
        std::chrono::duration<double, std::milli>(BenchClock::now() - start).count());
  }
  out.read_to_reply =
      minus(scrape_latency(port, bus_name)["command_to_reply"], after["command_to_reply"]);
  child.close_stdin();
  child.wait_exit(10s);
  (*exporter).reset();
  (*service)->stop();
  return out;
}

// ---------------------------------------------------------------------------
// Bus load per state: one hand on the simulated line, simulated time.

class NullObserver final : public dh3::hand::HandObserver {
 public:
  void on_state(const dh3::hand::HandState&) override {}
  void on_event(const dh3::hand::HandEvent&) override {}
  void on_link(dh3::bus::LinkState) override {}
};

struct StateLoad {
  const char* state;
  double frames_per_second;  // requests and replies
};

std::vector<StateLoad> bus_load_per_state() {
  using dh3::hand::Command;
  using dh3::hand::CommandKind;
  struct Case {
    const char* name;
    std::function<void(dh3::hand::BusScheduler&, dh3::sim::SimBus&, dh3::FakeClock&)> enter;
  };
  const auto submit = [](dh3::hand::BusScheduler& s, CommandKind kind, std::int32_t value) {
    Command c;
    c.kind = kind;
    c.value = value;
    s.submit(1, c, [](const dh3::hand::CommandResult&) {});
  };
  const std::vector<Case> cases = {
      {"idle, holding nothing", [](auto&, auto&, auto&) {}},
      {"holding an object",
       [&](auto& s, auto& bus, auto&) {
         // Just below the open fingers: caught within a second at 1 %/s.
         bus.with_hand(1, [](dh3::sim::SimHand& h) { h.place_object(99); });
         submit(s, CommandKind::grasp, 50);
       }},
      {"closing (grasp under way)",
       [&](auto& s, auto&, auto&) { submit(s, CommandKind::grasp, 50); }},
      {"opening (release under way)",
       [&](auto& s, auto&, auto&) { submit(s, CommandKind::move_to, 100); }},
      {"rotating", [&](auto& s, auto&, auto&) { submit(s, CommandKind::rotate_to, 100); }},
  };
  std::vector<StateLoad> out;
  for (const auto& c : cases) {
    dh3::FakeClock clock;
    dh3::sim::SimHandOptions hand;
    hand.id = 1;
    hand.init_time = 100ms;
    hand.position_speed = 1.0;  // motions outlast the measurement
    hand.rotation_speed = 1.0;
    dh3::sim::SimBusOptions line;
    line.bit_rate = 500'000;
    auto bus = std::make_unique<dh3::sim::SimBus>("sim:load", std::vector{hand}, clock, line);
    auto* sim_bus = bus.get();
    NullObserver observer;
    dh3::hand::BusScheduler scheduler("load", std::move(bus), {{1, ""}}, {}, clock, observer);
    const auto run = [&](dh3::Duration d) {
      for (auto until = clock.now() + d; clock.now() < until;) {
        clock.advance(1ms);
        scheduler.step();
      }
    };
    run(1s);
    submit(scheduler, CommandKind::initialize, 0);
    run(1s);
    if (std::string(c.name) == "opening (release under way)") {
      submit(scheduler, CommandKind::move_to, 0);  // off the end stop, so opening has room
      run(15s);
    }
    c.enter(scheduler, *sim_bus, clock);
    run(2s);
    const std::uint64_t before = sim_bus->frames_sent() + sim_bus->frames_delivered();
    run(10s);
    const std::uint64_t frames = sim_bus->frames_sent() + sim_bus->frames_delivered() - before;
    out.push_back({c.name, static_cast<double>(frames) / 10.0});
  }
  return out;
}

std::string config_for_sim(int hands) {
  std::string yaml =
      "buses:\n"
      "  - name: can0\n"
      "    spec: sim:" +
      dh3::bench::hand_ids(hands) +
      "\n"
      "    sim: {bit_rate: 500000, init_time_ms: 100}\n";
  return yaml;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Event latency: simulated change to the event at a client process"};
  dh3::bench::CommonOptions common;
  dh3::bench::add_common_options(app, common);
  int cycles = 20;
  int many_cycles = 40;
  std::string moving_ms;
  std::string position_moving_ms;
  app.add_option("--cycles", cycles, "drop / release / grasp cycles with 1 hand");
  app.add_option("--many-cycles", many_cycles, "cycles with 32 hands");
  app.add_option("--poll-interval-moving-ms", moving_ms,
                 "poll_interval_moving_ms for the buses (default: the service's)");
  app.add_option("--poll-interval-position-moving-ms", position_moving_ms,
                 "poll_interval_position_moving_ms for the buses (default: the service's; 0: no "
                 "position read during a motion)");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::warn);
  if (common.role == "client") return run_client(common);

  std::string extra =
      moving_ms.empty() ? std::string() : "    poll_interval_moving_ms: " + moving_ms + "\n";
  if (!position_moving_ms.empty()) {
    extra += "    poll_interval_position_moving_ms: " + position_moving_ms + "\n";
  }
  std::printf("\nEvent latency: simulated change -> event at a client process, ms\n");
  int lost = 0;
  std::string violation_count;
  std::optional<Latencies> one;
  std::optional<Latencies> many;
  {
    // dh3-sim counts frames to a hand closer than 20 ms (`violations`).
    dh3::test::Process sim(DH3_SIM_PATH,
                           {"--listen", "127.0.0.1:0", "--hands", "2", "--init-time-ms", "100",
                            "--min-interval-ms", "20", "--log-level", "warn"});
    const auto line = sim.wait_for_line("listening ", 10s);
    if (!line) {
      std::fprintf(stderr, "dh3-sim did not start\n");
      return 1;
    }
    const std::string config =
        "buses:\n  - name: box\n    spec: tcp:" + line->substr(std::string("listening ").size()) +
        "\n    hands: [{id: 2}]\n" + extra;
    one = run_scenario(config, dh3::bench::bench_domain(), {2}, cycles, &sim);
    if (!one) return 1;
    lost += one->lost;
    sim.write_line("violations");
    const auto violations = sim.wait_for_line("ok", 5s);
    violation_count = violations ? violations->substr(3) : "unknown";
    sim.write_line("quit");
    sim.wait_exit(5s);
  }
  {
    std::vector<unsigned> ids;
    for (unsigned id = 1; id <= 32; ++id) ids.push_back(id);
    many = run_scenario(config_for_sim(32) + extra, dh3::bench::bench_domain() + 1, ids,
                        many_cycles, nullptr);
    if (!many) return 1;
    lost += many->lost;
  }
  const char* kOne = "1 hand, dh3-sim over TCP";
  const char* kMany = "32 hands holding, 500 kbps line";
  std::printf(
      "(floor: the hand's frame spacing, command interval + margin; ratio = figure / floor)\n");
  std::printf("| %-32s | %-8s | %5s | %7s | %7s | %7s | %5s | %6s | %6s |\n", "scenario", "event",
              "n", "p50", "p99", "max", "floor", "p50/fl", "p99/fl");
  std::printf("|%s|%s|%s|%s|%s|%s|%s|%s|%s|\n", std::string(34, '-').c_str(),
              std::string(10, '-').c_str(), std::string(7, '-').c_str(),
              std::string(9, '-').c_str(), std::string(9, '-').c_str(), std::string(9, '-').c_str(),
              std::string(7, '-').c_str(), std::string(8, '-').c_str(),
              std::string(8, '-').c_str());
  print_rows(kOne, *one);
  print_rows(kMany, *many);
  std::printf("events not seen within 5 s: %d\n", lost);
  std::printf("frames to the hand closer than 20 ms, as dh3-sim saw them: %s\n",
              violation_count.c_str());
  std::printf(
      "\nThe service's histograms (its /metrics, scraped before and after the cycles) against the "
      "client's figures, ms\n(agree: the client's figure within one bucket width of the "
      "histogram's estimate, which is histogram_quantile's)\n");
  std::printf("| %-32s | %-30s | %5s | %7s | %7s | %6s | %-5s |\n", "scenario", "what", "n",
              "client", "histo", "bucket", "agree");
  print_histograms(kOne, *one);
  print_histograms(kMany, *many);
  if (!common.json_path.empty()) {
    std::ofstream(common.json_path)
        << "{\"event_latency\":[" << json_rows << "],\"lost\":" << lost << "}\n";
  }

  std::printf("\nBus load per hand by state (simulated 500 kbps line, 111-bit frames)\n");
  std::printf("| %-28s | %9s | %12s |\n", "state", "frames/s", "% of line");
  std::printf("|%s|%s|%s|\n", std::string(30, '-').c_str(), std::string(11, '-').c_str(),
              std::string(14, '-').c_str());
  for (const auto& load : bus_load_per_state()) {
    std::printf("| %-28s | %9.1f | %11.2f%% |\n", load.state, load.frames_per_second,
                100.0 * load.frames_per_second * 111.0 / 500'000.0);
  }
  return 0;
}
