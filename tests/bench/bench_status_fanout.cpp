// Status fan-out (benchmark 4): dh3-service (a child process) with 64
// simulated hands kept moving, and 1, 4 and 16 subscribing clients. Reports the
// status samples per second the service published and each client received,
// and the service's CPU time (utime + stime from /proc) per published sample.
//
// Every subscriber is its own process with its own dh3::Client, as separate
// programs on a cell controller would be: participants in one process would
// get the samples by Fast DDS's intraprocess delivery, not over the transport.
// The hands are kept moving by a raw DDS request writer in this process (MOVE
// to 0 and 100 in turn, every 600 ms per hand) that reads no statuses, so it is
// no subscriber itself. The service's default status timing applies (polled
// every 50 ms while moving); a status sample goes out when a hand's state
// changes. Published samples are counted from the samples' update_seq (one
// increment per sample written for that hand), so samples a slow client never
// received still count as published.
//
//   bench_status_fanout [--seconds S] [--json FILE]
//   bench_status_fanout --role subscriber --domain D --service NAME   (internal)

#include <spdlog/spdlog.h>

#include <array>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "dh3/client.hpp"
#include "dh3/contract/qos.hpp"
#include "raw_dds.hpp"

namespace {

using namespace std::chrono_literals;
using namespace dh3;
using bench::BenchClock;

constexpr int kHands = 64;

std::string service_config() {
  return "buses:\n"
         "  - name: bus0\n"
         "    spec: sim:" +
         bench::hand_ids(kHands) +
         "\n"
         "    command_interval_ms: 0\n"
         "    sim: {init_time_ms: 50}\n";
}

/// Counts the status samples it receives and, per hand, the newest update_seq.
/// Prints "ready" once it has every hand's status, then answers "go" and
/// "stop" on stdin; after "stop" prints "counted DELIVERED PUBLISHED SECONDS".
int run_subscriber(int domain, const std::string& service) {
  ClientOptions options;
  options.domain = domain;
  options.participant_name = "dh3-bench-subscriber";
  Client client(options);
  std::mutex mutex;
  std::uint64_t delivered = 0;
  std::array<std::uint64_t, 256> newest_seq{};
  auto subscription = client.subscribe_status([&](const HandStatus& status) {
    std::lock_guard lock(mutex);
    ++delivered;
    newest_seq[status.address.can_id] =
        std::max(newest_seq[status.address.can_id], status.update_seq);
  });
  const auto deadline = BenchClock::now() + 60s;
  while (BenchClock::now() < deadline) {
    std::size_t seen = 0;
    for (const auto& status : client.hands()) seen += status.address.service == service ? 1 : 0;
    if (seen >= kHands) break;
    std::this_thread::sleep_for(20ms);  // polling the hands seen
  }
  std::printf("ready\n");
  std::fflush(stdout);

  const auto snapshot = [&] {
    std::lock_guard lock(mutex);
    std::uint64_t published = 0;
    for (const auto seq : newest_seq) published += seq;
    return std::pair{delivered, published};
  };
  std::string line;
  std::pair<std::uint64_t, std::uint64_t> start{};
  auto started = BenchClock::now();
  while (std::getline(std::cin, line)) {
    if (line == "go") {
      start = snapshot();
      started = BenchClock::now();
    } else if (line == "stop") {
      const auto end = snapshot();
      const double seconds = std::chrono::duration<double>(BenchClock::now() - started).count();
      std::printf("counted %llu %llu %.3f\n",
                  static_cast<unsigned long long>(end.first - start.first),
                  static_cast<unsigned long long>(end.second - start.second), seconds);
      std::fflush(stdout);
    }
  }
  return 0;
}

/// Sends MOVE requests that keep every hand moving, and INITIALIZE first.
class Mover {
 public:
  Mover(int domain, const std::string& service) : raw_(domain, "dh3-bench-mover", false) {
    if (!raw_.ok()) return;
    writer_ = raw_.publisher->create_datawriter(raw_.request_topic,
                                                contract::writer_qos(contract::TopicRole::request));
    request_.client_id(raw_.client_id());
    request_.hand().service(service);
    request_.hand().bus("bus0");
  }
  ~Mover() { stop(); }
  Mover(const Mover&) = delete;
  Mover& operator=(const Mover&) = delete;

  /// Initializes every hand, then moves them until stop().
  void start() {
    thread_ = std::thread([this] {
      // Requests are volatile: send none before the service's reader matched.
      const auto deadline = BenchClock::now() + 30s;
      eprosima::fastdds::dds::PublicationMatchedStatus matched;
      while (writer_ != nullptr && !stop_.load() && BenchClock::now() < deadline &&
             (writer_->get_publication_matched_status(matched), matched.current_count == 0)) {
        std::this_thread::sleep_for(10ms);  // polling the match state
      }
      send_all(msg::INITIALIZE, 0);
      for (int stroke = 0; !stop_.load(); ++stroke) {
        // Initialization (50 ms in the sim) is long done by the first stroke.
        std::this_thread::sleep_for(600ms);  // the motion's pace, not a wait for an event
        send_all(msg::MOVE, stroke % 2 == 0 ? 0 : 100);
      }
    });
  }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }

 private:
  void send_all(msg::CommandType command, std::int32_t value) {
    if (writer_ == nullptr) return;
    for (int id = 1; id <= kHands; ++id) {
      request_.request_seq(++seq_);
      request_.hand().can_id(static_cast<std::uint16_t>(id));
      request_.command(command);
      request_.value(value);
      writer_->write(&request_);
    }
  }
  bench::RawParticipant raw_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  msg::CommandRequest request_;
  std::uint64_t seq_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

struct Row {
  int clients = 0;
  double published_per_s = 0;
  double delivered_per_s = 0;  ///< all clients together
  double min_client_per_s = 0;
  double max_client_per_s = 0;
  double service_cpu_us_per_sample = 0;
  double service_cpu_percent = 0;
};

Row measure(int clients, int domain, const std::string& service, pid_t service_pid,
            double seconds) {
  std::vector<std::unique_ptr<test::Process>> subscribers;
  for (int i = 0; i < clients; ++i) {
    subscribers.push_back(std::make_unique<test::Process>(
        bench::self_path(),
        std::vector<std::string>{"--role", "subscriber", "--domain", std::to_string(domain),
                                 "--service", service}));
  }
  for (auto& subscriber : subscribers) subscriber->wait_for_line("ready", 90s);
  std::this_thread::sleep_for(1s);  // let discovery traffic settle before the window

  const double cpu_before = bench::cpu_seconds_of(service_pid);
  const auto started = BenchClock::now();
  for (auto& subscriber : subscribers) subscriber->write_line("go");
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));  // the window
  for (auto& subscriber : subscribers) subscriber->write_line("stop");
  const double cpu = bench::cpu_seconds_of(service_pid) - cpu_before;
  const double window = std::chrono::duration<double>(BenchClock::now() - started).count();

  Row row;
  row.clients = clients;
  row.min_client_per_s = 1e18;
  double published_per_s = 0;
  for (auto& subscriber : subscribers) {
    const auto line = subscriber->wait_for_line("counted", 30s);
    unsigned long long delivered = 0;
    unsigned long long published = 0;
    double own_window = 1;
    if (!line || std::sscanf(line->c_str(), "counted %llu %llu %lf", &delivered, &published,
                             &own_window) != 3) {
      std::fprintf(stderr, "a subscriber did not report\n");
      continue;
    }
    const double rate = static_cast<double>(delivered) / own_window;
    row.delivered_per_s += rate;
    row.min_client_per_s = std::min(row.min_client_per_s, rate);
    row.max_client_per_s = std::max(row.max_client_per_s, rate);
    published_per_s = std::max(published_per_s, static_cast<double>(published) / own_window);
    subscriber->close_stdin();
  }
  for (auto& subscriber : subscribers) subscriber->wait_exit(20s);
  row.published_per_s = published_per_s;
  row.service_cpu_percent = 100 * cpu / window;
  if (published_per_s > 0) row.service_cpu_us_per_sample = 1e6 * cpu / (published_per_s * window);
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Status fan-out: 64 hands to 1, 4 and 16 subscribing clients"};
  bench::CommonOptions common;
  bench::add_common_options(app, common);
  double seconds = 5;
  app.add_option("--seconds", seconds, "Seconds measured per row")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  auto& [json_path, role, domain, service] = common;
  spdlog::set_level(spdlog::level::warn);
  if (role == "subscriber") return run_subscriber(domain, service);

  domain = bench::bench_domain();
  service = "fanout";
  bench::ServiceChild child(service_config(), domain, service, false);
  Mover mover(domain, service);
  mover.start();
  std::vector<Row> rows;
  for (const int clients : {1, 4, 16}) {
    rows.push_back(measure(clients, domain, service, child.pid(), seconds));
  }
  mover.stop();
  const double service_hwm =
      static_cast<double>(bench::status_kib(child.pid(), "VmHWM:").value_or(0));
  child.stop();

  std::printf("Status fan-out: dh3-service with %d moving sim hands, %.0f s per row (shm)\n",
              kHands, seconds);
  std::printf("%7s %12s %14s %12s %12s %14s %9s\n", "clients", "published/s", "delivered/s",
              "client min/s", "client max/s", "svc cpu us/smp", "svc cpu%");
  for (const Row& r : rows) {
    std::printf("%7d %12.0f %14.0f %12.0f %12.0f %14.1f %8.1f%%\n", r.clients, r.published_per_s,
                r.delivered_per_s, r.min_client_per_s, r.max_client_per_s,
                r.service_cpu_us_per_sample, r.service_cpu_percent);
  }
  std::printf("service VmHWM %.1f MiB\n", service_hwm / 1024);
  if (!json_path.empty()) {
    std::FILE* f = std::fopen(json_path.c_str(), "w");
    if (f == nullptr) {
      std::perror(json_path.c_str());
      return 1;
    }
    std::fprintf(f, "{\"benchmark\":\"status_fanout\",\"hands\":%d,\"seconds\":%g,\"rows\":[",
                 kHands, seconds);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      std::fprintf(f,
                   "%s{\"clients\":%d,\"published_per_s\":%.1f,\"delivered_per_s\":%.1f,"
                   "\"client_min_per_s\":%.1f,\"client_max_per_s\":%.1f,"
                   "\"service_cpu_us_per_sample\":%.2f,\"service_cpu_percent\":%.2f}",
                   i == 0 ? "" : ",", r.clients, r.published_per_s, r.delivered_per_s,
                   r.min_client_per_s, r.max_client_per_s, r.service_cpu_us_per_sample,
                   r.service_cpu_percent);
    }
    std::fprintf(f, "]}\n");
    std::fclose(f);
  }
  return 0;
}
