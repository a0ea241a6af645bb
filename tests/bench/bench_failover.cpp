// Death detection (docs/failover.md): how long after dh3-service is killed
// (SIGKILL) or frozen (SIGSTOP) the C++ client library reports its hand
// OFFLINE and ends a call in flight to it (an INITIALIZE, which takes ten
// minutes here) SERVICE_LOST, over many kills; and what the owner liveliness costs at rest, as
// the bytes and CPU time of writers that assert it against writers that do
// not, with their readers, all in this process.
//
//   bench_failover --kills 20 [--signal STOP]
//   unshare -n sh -c 'ip link set lo up; bench_failover --kills 0 --cost-seconds 20 --writers 64'
// The cost's bytes are the loopback interface's: run it in a network
// namespace of its own (as above) so that nothing else is counted.

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <condition_variable>
#include <csignal>
#include <future>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <memory>
#include <mutex>
#include <random>
#include <thread>

#include "bench_util.hpp"
#include "dh3/client.hpp"
#include "dh3/contract/ownership.hpp"
#include "dh3/contract/participant_setup.hpp"
#include "dh3/contract/qos.hpp"
#include "dh3/registers.hpp"

namespace {

using dh3::bench::BenchClock;
namespace fdds = eprosima::fastdds::dds;

std::string sim_config() {
  return "buses:\n"
         "  - name: bus0\n"
         "    spec: sim\n"
         "    init_timeout_ms: 1200000\n"
         "    sim: {init_time_ms: 600000}\n"
         "    hands:\n"
         "      - {id: 1}\n"
         "      - {id: 2}\n";
}

/// Waits for the hand's first OFFLINE event after arm().
class OfflineWatch {
 public:
  void arm() {
    std::lock_guard lock(mutex_);
    seen_.reset();
  }
  void on_event(const dh3::HandEvent& event) {
    if (event.kind != dh3::EventKind::offline) return;
    std::lock_guard lock(mutex_);
    if (!seen_) seen_ = BenchClock::now();
    changed_.notify_all();
  }
  std::optional<BenchClock::time_point> wait(std::chrono::seconds timeout) {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout, [this] { return seen_.has_value(); });
    return seen_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<BenchClock::time_point> seen_;
};

/// What one kill took at the client, in ms from the signal.
struct Seen {
  double offline_ms = 0;
  std::optional<double> call_ended_ms;  ///< nullopt: not SERVICE_LOST within 30 s
};

/// One kill: the service started, its hand online at the client and an
/// INITIALIZE of it in flight, then the signal after a random pause (any
/// phase of the assertion period); nullopt if no OFFLINE came within 30 s.
std::optional<Seen> one_kill(dh3::Client& client, int domain, const std::string& name,
                             int signal_number, std::mt19937& random) {
  dh3::bench::ServiceChild service(sim_config(), domain, name, true);
  const dh3::HandAddress address{name, "bus0", 1};
  auto hand = client.wait_for_hand(address.to_string(), std::chrono::seconds(30));
  if (!hand || !hand->wait_until([](const dh3::HandStatus& s) { return s.online; },
                                 std::chrono::seconds(30))) {
    std::fprintf(stderr, "the service's hand never came online\n");
    return std::nullopt;
  }
  OfflineWatch watch;
  auto subscription = hand->subscribe([&watch](const dh3::HandEvent& e) { watch.on_event(e); });
  // Its end timed where it is told, on the callback thread (as the OFFLINE event is).
  auto ended_promise = std::make_shared<std::promise<std::optional<BenchClock::time_point>>>();
  auto pending = ended_promise->get_future();
  hand->initialize_async(
      [ended_promise](const dh3::Reply& reply) {
        ended_promise->set_value(reply.code == dh3::Code::service_lost
                                     ? std::optional(BenchClock::now())
                                     : std::nullopt);
      },
      std::chrono::seconds(120));
  // Requests of one client arrive in order: once hand 2's read is answered,
  // the service has the INITIALIZE.
  if (!client.hand(dh3::HandAddress{name, "bus0", 2}).read(dh3::reg::position)) {
    std::fprintf(stderr, "the read behind the INITIALIZE was not answered\n");
    return std::nullopt;
  }
  std::this_thread::sleep_for(
      std::chrono::milliseconds(std::uniform_int_distribution<int>(300, 700)(random)));
  watch.arm();
  const auto killed = BenchClock::now();
  service.signal(signal_number);
  const auto offline = watch.wait(std::chrono::seconds(30));
  std::optional<BenchClock::time_point> ended;
  if (pending.wait_for(std::chrono::seconds(30)) == std::future_status::ready) ended = pending.get();
  if (signal_number == SIGSTOP) service.signal(SIGKILL);
  if (!offline) return std::nullopt;
  Seen seen;
  seen.offline_ms = dh3::bench::micros_between(killed, *offline) / 1000.0;
  if (ended) seen.call_ended_ms = dh3::bench::micros_between(killed, *ended) / 1000.0;
  return seen;
}

void run_kills(int kills, int signal_number) {
  const int domain = dh3::bench::bench_domain();
  const std::string name = "bench-failover-" + std::to_string(::getpid());
  dh3::ClientOptions options;
  options.domain = domain;
  dh3::Client client(options);
  std::mt19937 random(std::random_device{}());
  std::vector<double> offline_ms;
  std::vector<double> ended_ms;
  int missed = 0;
  int not_ended = 0;
  for (int i = 0; i < kills; ++i) {
    if (const auto took = one_kill(client, domain, name, signal_number, random)) {
      offline_ms.push_back(took->offline_ms);
      if (took->call_ended_ms) {
        ended_ms.push_back(*took->call_ended_ms);
        std::printf("kill %2d: OFFLINE after %.0f ms, call ended SERVICE_LOST after %.0f ms\n",
                    i + 1, took->offline_ms, *took->call_ended_ms);
      } else {
        ++not_ended;
        std::printf("kill %2d: OFFLINE after %.0f ms, call not ended SERVICE_LOST within 30 s\n",
                    i + 1, took->offline_ms);
      }
    } else {
      ++missed;
      std::printf("kill %2d: no OFFLINE within 30 s\n", i + 1);
    }
    std::fflush(stdout);
  }
  const char* signal_text = signal_number == SIGSTOP ? "STOP" : "KILL";
  const auto p = dh3::bench::percentiles(offline_ms);
  std::printf("death detection, C++ client, SIG%s, %zu kills (%d missed): OFFLINE p50 %.0f ms, "
              "p99 %.0f ms, max %.0f ms (lease %lld ms, asserted every %lld ms)\n",
              signal_text, p.count, missed, p.p50, p.p99, p.max,
              static_cast<long long>(dh3::contract::kOwnerLease.count()),
              static_cast<long long>(dh3::contract::kOwnerAssertPeriod.count()));
  const auto e = dh3::bench::percentiles(ended_ms);
  std::printf("death detection, C++ client, SIG%s, %zu calls in flight (%d not ended): "
              "SERVICE_LOST p50 %.0f ms, p99 %.0f ms, max %.0f ms\n",
              signal_text, e.count, not_ended, e.p50, e.p99, e.max);
}

/// Bytes sent on the loopback interface so far (/proc/net/dev).
std::uint64_t loopback_tx_bytes() {
  std::ifstream in("/proc/net/dev");
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos || line.substr(0, colon).find("lo") == std::string::npos) {
      continue;
    }
    std::istringstream fields(line.substr(colon + 1));
    std::uint64_t value = 0;
    for (int index = 1; index <= 9 && fields >> value; ++index) {
      if (index == 9) return value;  // transmit bytes
    }
  }
  return 0;
}

/// `writers` participants with an owner writer each and one reader
/// participant; asserting or not, for `seconds`: bytes and CPU.
struct Cost {
  double bytes_per_s = 0;
  double cpu_percent = 0;
};

Cost measure(std::vector<fdds::DataWriter*>& writers, bool assert_liveliness, int seconds) {
  const auto start_bytes = loopback_tx_bytes();
  const double start_cpu = dh3::bench::cpu_seconds_of(::getpid());
  const auto start = BenchClock::now();
  const auto end = start + std::chrono::seconds(seconds);
  auto next = start;
  while (next < end) {
    if (assert_liveliness) {
      for (auto* writer : writers) writer->assert_liveliness();
    }
    next += dh3::contract::kOwnerAssertPeriod;
    std::this_thread::sleep_until(next);
  }
  const double elapsed = std::chrono::duration<double>(BenchClock::now() - start).count();
  Cost cost;
  cost.bytes_per_s = static_cast<double>(loopback_tx_bytes() - start_bytes) / elapsed;
  cost.cpu_percent = 100.0 * (dh3::bench::cpu_seconds_of(::getpid()) - start_cpu) / elapsed;
  return cost;
}

void run_cost(int writer_count, int seconds) {
  const int domain = dh3::bench::bench_domain();
  std::vector<std::unique_ptr<dh3::contract::Participant>> participants;
  std::vector<fdds::DataWriter*> writers;
  const auto make = [&](const std::string& name) -> dh3::contract::Participant* {
    dh3::contract::ParticipantOptions options;
    options.domain = domain;
    options.name = name;
    dh3::contract::SetupReport report;
    auto made = dh3::contract::Participant::create(options, report, nullptr);
    if (!made) {
      std::fprintf(stderr, "%s\n", made.error().c_str());
      std::exit(1);
    }
    participants.push_back(std::move(made).value());
    return participants.back().get();
  };
  fdds::DataReaderListener quiet;
  auto* reader_side = make("bench-failover-reader");
  reader_side->subscriber().create_datareader(
      reader_side->topics().owner,
      dh3::contract::reader_qos(dh3::contract::TopicRole::service_owner), &quiet,
      fdds::StatusMask::none());
  for (int i = 0; i < writer_count; ++i) {
    auto* writer_side = make("bench-failover-writer");
    auto* writer = writer_side->publisher().create_datawriter(
        writer_side->topics().owner,
        dh3::contract::writer_qos(dh3::contract::TopicRole::service_owner));
    dh3::msg::ServiceOwner claim;
    claim.service("cell" + std::to_string(i));
    writer->write(&claim);
    writers.push_back(writer);
  }
  // Discovery and the first samples settle before anything is counted.
  std::this_thread::sleep_for(std::chrono::seconds(5));
  const Cost quiet_cost = measure(writers, false, seconds);
  const Cost asserting = measure(writers, true, seconds);
  std::printf("liveliness at rest, %d writer(s) -> 1 reader, %d s each: not asserting %.0f B/s "
              "%.2f %% CPU, asserting %.0f B/s %.2f %% CPU: %.0f B/s and %.3f %% of a core per "
              "service and reader\n",
              writer_count, seconds, quiet_cost.bytes_per_s, quiet_cost.cpu_percent,
              asserting.bytes_per_s, asserting.cpu_percent,
              (asserting.bytes_per_s - quiet_cost.bytes_per_s) / writer_count,
              (asserting.cpu_percent - quiet_cost.cpu_percent) / writer_count);
  participants.clear();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dh3 death detection and the liveliness's cost at rest"};
  int kills = 20;
  std::string signal_name = "KILL";
  int cost_seconds = 0;
  int writers = 1;
  app.add_option("--kills", kills, "services to kill, one after the other");
  app.add_option("--signal", signal_name, "KILL or STOP")->check(CLI::IsMember({"KILL", "STOP"}));
  app.add_option("--cost-seconds", cost_seconds, "measure the cost at rest for this long (0: not)");
  app.add_option("--writers", writers, "owner writers (services) for the cost");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::warn);
  if (kills > 0) run_kills(kills, signal_name == "STOP" ? SIGSTOP : SIGKILL);
  if (cost_seconds > 0) run_cost(writers, cost_seconds);
  return 0;
}
