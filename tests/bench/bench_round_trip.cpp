// Command round trip and service overhead (benchmarks 1 and 2).
//
// Round trip: dh3::Client -> dh3-service (a child process) -> a simulated hand
// that answers at once (sim bus, reply delay 0, command interval 0) -> reply ->
// client, timed around two commands the hand answers at once: `read`, a
// READ_REGISTER of the closing force (0x0502; nothing in the hand's state
// changes), and `write`, Hand::set_force() (SET_CLOSING_FORCE, alternating 50
// and 60: the hand's state changes, so the service publishes a status sample
// before the reply, as it does for every state change). Next to it the
// middleware floor: a raw Fast DDS request/reply ping-pong on the contract's
// IDL types, topics, QoS and participant settings, with the same request and
// reply contents (so the same payload sizes), against an echo responder in a
// child process. Both over shared memory and over UDP loopback (udp_only).
// A third row, raw+hop, has the responder write each reply from a second
// thread its listener wakes, as dh3-service's bus loop is woken: what one
// thread hand-off costs on this machine.
// The responders always run in another process: participants in one process
// would use Fast DDS's intraprocess delivery and bypass the transport.
//
// Service overhead: dh3's Service in this process (default transports), traced
// (dds::ServiceOptions::test_seam_tracer) and with its bus wrapped to timestamp frames,
// driven by a dh3::Client in a child process. Reports the time from a request
// sample's take to its frame on the bus, and from the echo's arrival to the
// reply's write() call and return.
//
//   bench_round_trip [--count N] [--runs R] [--json FILE]
// With --runs, the round trips are measured R times (the service overhead
// once): each run's table and ratios, then per row the median ratio over the
// runs and how many runs met the goal (p50 at most 1.25 and p99 at most 1.5
// times raw's).
//   bench_round_trip --role responder --domain D [--udp-only] [--hop]  (internal)
//   bench_round_trip --role client --domain D --service NAME --count N --command read|write
//                                                                      (internal)

#include <spdlog/spdlog.h>

#include <algorithm>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "dh3/app/bus_setup.hpp"
#include "dh3/app/config.hpp"
#include "dh3/client.hpp"
#include "dh3/contract/dh3PubSubTypes.h"
#include "dh3/contract/participant.hpp"
#include "dh3/contract/qos.hpp"
#include "dh3/dds/service.hpp"
#include "dh3/protocol/codec.hpp"
#include "dh3/protocol/registers.hpp"
#include "dh3/registers.hpp"
#include "raw_dds.hpp"

namespace {

using namespace std::chrono_literals;
using namespace dh3;
using bench::BenchClock;
using bench::Percentiles;
namespace fdds = eprosima::fastdds::dds;
using contract::TopicRole;
using eprosima::fastrtps::types::ReturnCode_t;

constexpr int kWarmup = 500;
constexpr auto kReplyDeadline = 5s;

/// The service's config: one simulated hand that answers at once.
std::string service_config() {
  return "buses:\n"
         "  - name: bus0\n"
         "    spec: sim:1\n"
         "    command_interval_ms: 0\n"
         "    sim: {reply_delay_ms: 0}\n";
}

/// The command timed: READ_REGISTER 0x0502, or SET_CLOSING_FORCE 50/60.
enum class Command { read, write };

const char* command_name(Command command) {
  return command == Command::read ? "read" : "write";
}

struct Measured {
  std::vector<double> micros;
  int failed = 0;  ///< calls that ended with anything but OK
  /// Context switches per command over the measured commands: of this
  /// (requesting) process and of the responding one (dh3-service or raw echo).
  double requester_switches = 0;
  double responder_switches = 0;
  /// CPU time (user + system) per command in microseconds, the same two processes.
  double requester_cpu_us = 0;
  double responder_cpu_us = 0;
};

/// Context switches and CPU time of this process and the responder from construction on.
class SwitchCounter {
 public:
  explicit SwitchCounter(pid_t responder)
      : responder_(responder),
        self_(bench::context_switches_of(::getpid())),
        other_(responder > 0 ? bench::context_switches_of(responder) : 0),
        self_cpu_(bench::cpu_seconds_of(::getpid())),
        other_cpu_(responder > 0 ? bench::cpu_seconds_of(responder) : 0) {}
  void finish(Measured& measured, int count) const {
    measured.requester_switches =
        static_cast<double>(bench::context_switches_of(::getpid()) - self_) / count;
    measured.requester_cpu_us = 1e6 * (bench::cpu_seconds_of(::getpid()) - self_cpu_) / count;
    if (responder_ > 0) {
      measured.responder_cpu_us = 1e6 * (bench::cpu_seconds_of(responder_) - other_cpu_) / count;
      measured.responder_switches =
          static_cast<double>(bench::context_switches_of(responder_) - other_) / count;
    }
  }

 private:
  pid_t responder_;
  std::uint64_t self_;
  std::uint64_t other_;
  double self_cpu_;
  double other_cpu_;
};

/// Times `count` commands (after a warm-up) on hand 1 of `service`.
/// `responder`: the service's process id, to count its context switches (0: none).
Measured client_round_trips(int domain, const std::string& service, bool udp_only, int count,
                            Command command, pid_t responder) {
  Measured measured;
  ClientOptions options;
  options.domain = domain;
  options.participant_name = "dh3-bench-client";
  options.udp_only = udp_only;
  options.shared_memory = !udp_only;  // the "shm" rows: not the default
  Client client(options);
  auto hand = client.wait_for_hand(service + "/bus0/1", 30s);
  if (!hand) {
    std::fprintf(stderr, "no hand: %s\n", hand.message().c_str());
    measured.failed = count;
    return measured;
  }
  measured.micros.reserve(static_cast<std::size_t>(count));
  std::optional<SwitchCounter> switches;
  for (int i = 0; i < kWarmup + count; ++i) {
    if (i == kWarmup) switches.emplace(responder);
    const auto start = BenchClock::now();
    const Reply reply = command == Command::read
                            ? hand->read(reg::closing_force, kReplyDeadline)
                            : hand->set_force(i % 2 == 0 ? 50 : 60, std::nullopt, kReplyDeadline);
    const auto end = BenchClock::now();
    if (!reply) {
      ++measured.failed;
      continue;
    }
    if (i >= kWarmup) measured.micros.push_back(bench::micros_between(start, end));
  }
  if (switches) switches->finish(measured, count);
  return measured;
}

// ---------------------------------------------------------------------------
// Raw Fast DDS ping-pong on the contract's types and QoS

/// Answers every request at once with the reply the service would send for a
/// successful write: from the listener thread, or with `hop` from a thread of
/// its own that the listener wakes, as the service's bus loop is woken (this
/// measures what one such hand-off costs). Runs until stdin closes.
int run_responder(int domain, bool udp_only, bool hop) {
  class Echo final : public fdds::DataReaderListener {
   public:
    fdds::DataWriter* writer = nullptr;
    bool hop = false;
    ~Echo() override {
      {
        std::lock_guard lock(mutex_);
        stop_ = true;
      }
      wake_.notify_all();
      if (worker_.joinable()) worker_.join();
    }
    void start() {
      if (!hop) return;
      worker_ = std::thread([this] {
        std::unique_lock lock(mutex_);
        for (;;) {
          wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
          if (stop_) return;
          msg::CommandReply reply = std::move(queue_.front());
          queue_.pop_front();
          lock.unlock();
          writer->write(&reply);
          lock.lock();
        }
      });
    }
    void on_data_available(fdds::DataReader* reader) override {
      fdds::SampleInfo info;
      while (reader->take_next_sample(&request_, &info) == ReturnCode_t::RETCODE_OK) {
        if (!info.valid_data) continue;
        reply_.client_id(request_.client_id());
        reply_.request_seq(request_.request_seq());
        reply_.hand(request_.hand());
        reply_.command(request_.command());
        reply_.code(msg::OK);
        reply_.value(request_.value());
        // The hand's status, as dh3-service's replies carry it (same size).
        msg::HandStatus& status = reply_.status();
        status.service(request_.hand().service());
        status.bus(request_.hand().bus());
        status.can_id(request_.hand().can_id());
        status.online(true);
        status.closing_force(request_.value());
        status.firmware_version_text("4.1.2.0");
        status.update_seq(status.update_seq() + 1);
        if (!hop) {
          writer->write(&reply_);
          continue;
        }
        {
          std::lock_guard lock(mutex_);
          queue_.push_back(reply_);
        }
        wake_.notify_one();
      }
    }

   private:
    msg::CommandRequest request_;
    msg::CommandReply reply_;
    std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<msg::CommandReply> queue_;
    bool stop_ = false;
    std::thread worker_;
  };
  bench::RawParticipant raw(domain, "dh3-bench-raw-responder", udp_only);
  if (!raw.ok()) return 1;
  Echo echo;
  echo.hop = hop;
  echo.writer =
      raw.publisher->create_datawriter(raw.reply_topic, contract::writer_qos(TopicRole::reply));
  auto* reader = raw.subscriber->create_datareader(raw.request_topic,
                                                   contract::reader_qos(TopicRole::request), &echo);
  if (echo.writer == nullptr || reader == nullptr) return 1;
  echo.start();
  std::printf("ready\n");
  std::fflush(stdout);
  while (std::getchar() != EOF) {
  }
  reader->set_listener(nullptr);
  return 0;
}

/// Sends requests like the client library's and waits for each reply.
class RawRequester final : public fdds::DataReaderListener {
 public:
  RawRequester(int domain, bool udp_only, const std::string& service)
      : raw_(domain, "dh3-bench-raw-requester", udp_only) {
    if (!raw_.ok()) return;
    client_id_ = raw_.client_id();
    writer_ = raw_.publisher->create_datawriter(raw_.request_topic,
                                                contract::writer_qos(TopicRole::request));
    reader_ = raw_.subscriber->create_datareader(raw_.reply_topic,
                                                 contract::reader_qos(TopicRole::reply), this);
    request_.client_id(client_id_);
    request_.hand().service(service);
    request_.hand().bus("bus0");
    request_.hand().can_id(1);
    request_.command(msg::SET_CLOSING_FORCE);
  }
  ~RawRequester() override {
    if (reader_ != nullptr) reader_->set_listener(nullptr);
  }

  /// Waits until the responder's reader and writer are matched.
  bool wait_matched(std::chrono::seconds timeout) {
    const auto deadline = BenchClock::now() + timeout;
    while (writer_ != nullptr && reader_ != nullptr && BenchClock::now() < deadline) {
      fdds::PublicationMatchedStatus publication;
      fdds::SubscriptionMatchedStatus subscription;
      writer_->get_publication_matched_status(publication);
      reader_->get_subscription_matched_status(subscription);
      if (publication.current_count > 0 && subscription.current_count > 0) return true;
      std::this_thread::sleep_for(10ms);  // polling the match state
    }
    return false;
  }

  /// One request, then the wait for its reply; false if none came in time.
  bool round_trip(std::int32_t value) {
    const std::uint64_t seq = ++seq_;
    request_.request_seq(seq);
    request_.value(value);
    if (!writer_->write(&request_)) return false;
    std::unique_lock lock(mutex_);
    return replied_.wait_for(lock, kReplyDeadline, [&] { return last_reply_ == seq; });
  }

  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    while (reader->take_next_sample(&reply_, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || reply_.client_id() != client_id_) continue;
      {
        std::lock_guard lock(mutex_);
        last_reply_ = reply_.request_seq();
      }
      replied_.notify_all();
    }
  }

 private:
  bench::RawParticipant raw_;
  std::string client_id_;
  fdds::DataWriter* writer_ = nullptr;
  fdds::DataReader* reader_ = nullptr;
  msg::CommandRequest request_;
  msg::CommandReply reply_;  // the listener thread's
  std::uint64_t seq_ = 0;
  std::mutex mutex_;
  std::condition_variable replied_;
  std::uint64_t last_reply_ = 0;
};

Measured raw_round_trips(int domain, bool udp_only, int count, bool hop) {
  Measured measured;
  std::vector<std::string> args{"--role", "responder", "--domain", std::to_string(domain)};
  if (udp_only) args.emplace_back("--udp-only");
  if (hop) args.emplace_back("--hop");
  test::Process responder(bench::self_path(), args);
  if (!responder.wait_for_line("ready", 30s)) {
    std::fprintf(stderr, "the raw responder did not start\n");
    measured.failed = count;
    return measured;
  }
  {
    RawRequester requester(domain, udp_only, "bench");
    if (!requester.wait_matched(30s)) {
      std::fprintf(stderr, "the raw requester never matched the responder\n");
      measured.failed = count;
      return measured;
    }
    measured.micros.reserve(static_cast<std::size_t>(count));
    std::optional<SwitchCounter> switches;
    for (int i = 0; i < kWarmup + count; ++i) {
      if (i == kWarmup) switches.emplace(responder.pid());
      const auto start = BenchClock::now();
      const bool ok = requester.round_trip(i % 2 == 0 ? 50 : 60);
      const auto end = BenchClock::now();
      if (!ok) {
        ++measured.failed;
        continue;
      }
      if (i >= kWarmup) measured.micros.push_back(bench::micros_between(start, end));
    }
    if (switches) switches->finish(measured, count);
  }
  responder.close_stdin();
  responder.wait_exit(20s);
  return measured;
}

// ---------------------------------------------------------------------------
// Service overhead: in-process timestamps

/// The timestamps of one SET_CLOSING_FORCE command inside the service.
struct CommandTrace {
  std::uint64_t seq = 0;
  BenchClock::time_point taken, frame_sent, echo_received, reply_writing, reply_written;
  bool has_frame = false;
  bool has_echo = false;
};

/// Collects CommandTraces. The driver keeps one command in flight, so the
/// frame and echo on the bus belong to the newest request taken.
class TraceRecorder {
 public:
  explicit TraceRecorder(Command command)
      : access_(command == Command::read ? protocol::Access::read : protocol::Access::write) {}

  void on_point(dh3::dds::TracePoint point, std::uint64_t seq) {
    const auto now = BenchClock::now();
    std::lock_guard lock(mutex_);
    switch (point) {
      case dh3::dds::TracePoint::request_taken:
        current_ = CommandTrace{};
        current_.seq = seq;
        current_.taken = now;
        break;
      case dh3::dds::TracePoint::reply_writing:
        if (seq == current_.seq) current_.reply_writing = now;
        break;
      case dh3::dds::TracePoint::reply_written:
        if (seq == current_.seq && current_.has_frame && current_.has_echo) {
          current_.reply_written = now;
          done_.push_back(current_);
        }
        break;
    }
  }
  void on_frame_sent(const bus::CanFrame& frame) {
    if (!is_closing_force(frame, access_)) return;
    const auto now = BenchClock::now();
    std::lock_guard lock(mutex_);
    if (current_.seq != 0 && !current_.has_frame) {
      current_.frame_sent = now;
      current_.has_frame = true;
    }
  }
  void on_frame_received(const bus::CanFrame& frame, BenchClock::time_point now) {
    if (!is_closing_force(frame, std::nullopt)) return;
    std::lock_guard lock(mutex_);
    if (current_.has_frame && !current_.has_echo) {
      current_.echo_received = now;
      current_.has_echo = true;
    }
  }
  std::vector<CommandTrace> done() {
    std::lock_guard lock(mutex_);
    return done_;
  }

 private:
  static bool is_closing_force(const bus::CanFrame& frame, std::optional<protocol::Access> access) {
    const auto message = protocol::decode_payload(static_cast<std::uint8_t>(frame.id), frame.data);
    return message && message->reg == protocol::reg::kClosingForce &&
           (!access || message->access == *access);
  }
  protocol::Access access_;
  std::mutex mutex_;
  CommandTrace current_;
  std::vector<CommandTrace> done_;
};

/// Passes everything to the real bus and tells the recorder what crossed it.
class TracingBus final : public bus::Bus {
 public:
  TracingBus(std::unique_ptr<bus::Bus> inner, TraceRecorder& recorder)
      : inner_(std::move(inner)), recorder_(recorder) {}
  const std::string& spec() const override { return inner_->spec(); }
  Result<void, bus::BusError> send(const bus::CanFrame& frame) override {
    auto result = inner_->send(frame);
    if (result) recorder_.on_frame_sent(frame);
    return result;
  }
  Result<void, bus::BusError> receive(std::vector<bus::CanFrame>& out, Duration timeout) override {
    const std::size_t before = out.size();
    auto result = inner_->receive(out, timeout);
    const auto now = BenchClock::now();
    for (std::size_t i = before; i < out.size(); ++i) recorder_.on_frame_received(out[i], now);
    return result;
  }
  void wake() override { inner_->wake(); }
  bus::LinkState link_state() const override { return inner_->link_state(); }
  std::uint32_t bit_rate() const override { return inner_->bit_rate(); }

 private:
  std::unique_ptr<bus::Bus> inner_;
  TraceRecorder& recorder_;
};

struct Overhead {
  Command command = Command::read;
  Percentiles request_to_frame;
  Percentiles frame_to_echo;
  Percentiles echo_to_reply_write;
  Percentiles echo_to_reply_written;
  Percentiles reply_write_call;
  std::size_t commands = 0;
};

std::optional<Overhead> service_overhead(int domain, int count, Command command) {
  auto config = app::parse_config(service_config(), "bench");
  if (!config) {
    std::fprintf(stderr, "%s\n", config.error().message.c_str());
    return std::nullopt;
  }
  SystemClock clock;
  auto setups = app::open_buses(*config, clock);
  if (!setups) {
    std::fprintf(stderr, "%s\n", setups.error().c_str());
    return std::nullopt;
  }
  TraceRecorder recorder(command);
  for (auto& setup : *setups) {
    setup.bus = std::make_unique<TracingBus>(std::move(setup.bus), recorder);
  }
  dh3::dds::ServiceOptions options;
  options.name = "traced";
  options.participant.domain = domain;
  options.test_seam_tracer = [&recorder](dh3::dds::TracePoint point, std::uint64_t seq) {
    recorder.on_point(point, seq);
  };
  auto service = dh3::dds::Service::create(options, std::move(*setups), clock);
  if (!service) {
    std::fprintf(stderr, "%s\n", service.error().c_str());
    return std::nullopt;
  }
  if (auto started = (*service)->start(); !started) {
    std::fprintf(stderr, "%s\n", started.error().c_str());
    return std::nullopt;
  }
  test::Process client(
      bench::self_path(),
      {"--role", "client", "--domain", std::to_string(domain), "--service", options.name, "--count",
       std::to_string(count), "--command", command_name(command)});
  const auto line = client.wait_for_line("done", 600s);
  client.wait_exit(20s);
  (*service)->stop();
  if (!line) {
    std::fprintf(stderr, "the traced service's client did not finish\n");
    return std::nullopt;
  }
  auto traces = recorder.done();
  // The client's warm-up commands come first.
  const std::size_t skip = std::min<std::size_t>(kWarmup, traces.size());
  std::vector<double> to_frame, frame_to_echo, to_write, to_written, write_call;
  for (std::size_t i = skip; i < traces.size(); ++i) {
    const CommandTrace& t = traces[i];
    to_frame.push_back(bench::micros_between(t.taken, t.frame_sent));
    frame_to_echo.push_back(bench::micros_between(t.frame_sent, t.echo_received));
    to_write.push_back(bench::micros_between(t.echo_received, t.reply_writing));
    to_written.push_back(bench::micros_between(t.echo_received, t.reply_written));
    write_call.push_back(bench::micros_between(t.reply_writing, t.reply_written));
  }
  Overhead overhead;
  overhead.command = command;
  overhead.commands = to_frame.size();
  overhead.request_to_frame = bench::percentiles(to_frame);
  overhead.frame_to_echo = bench::percentiles(frame_to_echo);
  overhead.echo_to_reply_write = bench::percentiles(to_write);
  overhead.echo_to_reply_written = bench::percentiles(to_written);
  overhead.reply_write_call = bench::percentiles(write_call);
  return overhead;
}

// ---------------------------------------------------------------------------

struct Row {
  std::string transport;
  std::string path;
  Percentiles latency;
  int failed = 0;
  double requester_switches = 0;
  double responder_switches = 0;
  double requester_cpu_us = 0;
  double responder_cpu_us = 0;
};

Row make_row(const std::string& transport, const std::string& path, Measured measured) {
  return Row{transport,
             path,
             bench::percentiles(measured.micros),
             measured.failed,
             measured.requester_switches,
             measured.responder_switches,
             measured.requester_cpu_us,
             measured.responder_cpu_us};
}

void print_percentiles(const char* name, const Percentiles& p) {
  std::printf("%-36s %9.1f %9.1f %9.1f %9.1f\n", name, p.p50, p.p90, p.p99, p.max);
}

/// The goal: dh3's round trip at most this many times raw's.
constexpr double kGoalP50 = 1.25;
constexpr double kGoalP99 = 1.5;

struct Ratio {
  std::string transport;
  std::string path;
  double p50 = 0;
  double p99 = 0;
  [[nodiscard]] bool met() const { return p50 <= kGoalP50 && p99 <= kGoalP99; }
};

/// One run: dh3 read and write, raw and raw+hop, on shm and UDP.
std::vector<Row> measure_rows(int domain, int count) {
  std::vector<Row> rows;
  for (const bool udp_only : {false, true}) {
    const std::string transport = udp_only ? "udp" : "shm";
    {
      bench::ServiceChild service(service_config(), domain, "bench", udp_only);
      for (const Command command : {Command::read, Command::write}) {
        rows.push_back(
            make_row(transport, std::string("dh3 ") + command_name(command),
                     client_round_trips(domain, "bench", udp_only, count, command, service.pid())));
      }
    }
    rows.push_back(make_row(transport, "raw", raw_round_trips(domain, udp_only, count, false)));
    rows.push_back(make_row(transport, "raw+hop", raw_round_trips(domain, udp_only, count, true)));
  }
  return rows;
}

/// Every row but raw against the raw row of its transport.
std::vector<Ratio> ratios_of(const std::vector<Row>& rows) {
  std::vector<Ratio> ratios;
  for (const Row& r : rows) {
    if (r.path == "raw") continue;  // raw+hop shows what one thread hand-off adds
    const auto raw = std::find_if(rows.begin(), rows.end(), [&](const Row& other) {
      return other.transport == r.transport && other.path == "raw";
    });
    if (raw == rows.end() || raw->latency.p50 <= 0 || raw->latency.p99 <= 0) continue;
    ratios.push_back(Ratio{r.transport, r.path, r.latency.p50 / raw->latency.p50,
                           r.latency.p99 / raw->latency.p99});
  }
  return ratios;
}

double load_average() {
  std::ifstream in("/proc/loadavg");
  double one_minute = 0;
  in >> one_minute;
  return one_minute;
}

void print_rows(const std::vector<Row>& rows) {
  std::printf("%-5s %-9s %8s %9s %9s %9s %9s %7s %7s %7s %7s %7s\n", "trans", "path", "count",
              "p50", "p90", "p99", "max", "failed", "cs/req", "cs/rsp", "cpu/req", "cpu/rsp");
  for (const Row& r : rows) {
    std::printf("%-5s %-9s %8zu %9.1f %9.1f %9.1f %9.1f %7d %7.2f %7.2f %7.1f %7.1f\n",
                r.transport.c_str(), r.path.c_str(), r.latency.count, r.latency.p50, r.latency.p90,
                r.latency.p99, r.latency.max, r.failed, r.requester_switches, r.responder_switches,
                r.requester_cpu_us, r.responder_cpu_us);
  }
}

void print_ratios(const std::vector<Ratio>& ratios) {
  std::printf("%-5s %-9s %12s %12s   goal p50<=%.2f p99<=%.2f\n", "trans", "path", "/raw p50",
              "/raw p99", kGoalP50, kGoalP99);
  for (const Ratio& r : ratios) {
    std::printf("%-5s %-9s %12.2f %12.2f   %s\n", r.transport.c_str(), r.path.c_str(), r.p50, r.p99,
                r.met() ? "met" : "not met");
  }
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  if (n == 0) return 0;
  return n % 2 == 1 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

int run_benchmark(int count, int runs, const std::string& json_path) {
  const int domain = bench::bench_domain();
  std::vector<std::vector<Row>> all_rows;
  std::vector<std::vector<Ratio>> all_ratios;
  std::vector<double> loads;
  for (int run = 1; run <= runs; ++run) {
    all_rows.push_back(measure_rows(domain, count));
    all_ratios.push_back(ratios_of(all_rows.back()));
    loads.push_back(load_average());
    std::printf(
        "Run %d of %d. Command round trip: client -> dh3-service -> sim hand answering at once -> "
        "client, vs raw Fast DDS ping-pong; %d commands each, microseconds; load average %.2f\n",
        run, runs, count, loads.back());
    print_rows(all_rows.back());
    std::printf(
        "(per command, of the requesting process and of the responding one, dh3-service or the "
        "raw\n echo: cs = context switches of all their threads, cpu = user + system CPU "
        "microseconds)\n");
    print_ratios(all_ratios.back());
    std::printf("\n");
    std::fflush(stdout);
  }
  // The verdict: per row, the median of the runs' ratios, and how many runs met the goal.
  std::vector<Ratio> medians;
  std::vector<int> met_runs;
  for (std::size_t i = 0; i < all_ratios.front().size(); ++i) {
    std::vector<double> p50s, p99s;
    int met = 0;
    for (const auto& ratios : all_ratios) {
      if (i >= ratios.size()) continue;
      p50s.push_back(ratios[i].p50);
      p99s.push_back(ratios[i].p99);
      met += ratios[i].met() ? 1 : 0;
    }
    const Ratio& first = all_ratios.front()[i];
    medians.push_back(Ratio{first.transport, first.path, median(p50s), median(p99s)});
    met_runs.push_back(met);
  }
  if (runs > 1) {
    std::printf("Median of %d runs (load average %.2f-%.2f)\n", runs,
                *std::min_element(loads.begin(), loads.end()),
                *std::max_element(loads.begin(), loads.end()));
    std::printf("%-5s %-9s %12s %12s %9s   goal p50<=%.2f p99<=%.2f\n", "trans", "path",
                "median p50", "median p99", "runs met", kGoalP50, kGoalP99);
    for (std::size_t i = 0; i < medians.size(); ++i) {
      std::printf("%-5s %-9s %12.2f %12.2f %5d/%-3d   %s\n", medians[i].transport.c_str(),
                  medians[i].path.c_str(), medians[i].p50, medians[i].p99, met_runs[i], runs,
                  medians[i].met() ? "met" : "not met");
    }
  }
  const std::vector<Row>& rows = all_rows.back();
  std::string ratios_json;
  for (std::size_t i = 0; i < medians.size(); ++i) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "%s{\"transport\":\"%s\",\"path\":\"%s\",\"median_p50\":%.3f,"
                  "\"median_p99\":%.3f,\"runs_met\":%d}",
                  ratios_json.empty() ? "" : ",", medians[i].transport.c_str(),
                  medians[i].path.c_str(), medians[i].p50, medians[i].p99, met_runs[i]);
    ratios_json += text;
  }
  std::vector<Overhead> overheads;
  for (const Command command : {Command::read, Command::write}) {
    if (auto overhead = service_overhead(domain, count, command)) overheads.push_back(*overhead);
  }

  for (const Overhead& o : overheads) {
    std::printf(
        "\nService overhead, dh3 %s (in-process timestamps, shm, %zu commands), microseconds\n",
        command_name(o.command), o.commands);
    std::printf("%-36s %9s %9s %9s %9s\n", "interval", "p50", "p90", "p99", "max");
    print_percentiles("request taken -> frame sent", o.request_to_frame);
    print_percentiles("(sim) frame sent -> echo received", o.frame_to_echo);
    print_percentiles("echo received -> reply write()", o.echo_to_reply_write);
    print_percentiles("echo received -> write() returned", o.echo_to_reply_written);
    print_percentiles("reply write() call", o.reply_write_call);
  }
  if (!json_path.empty()) {
    std::FILE* f = std::fopen(json_path.c_str(), "w");
    if (f == nullptr) {
      std::perror(json_path.c_str());
      return 1;
    }
    std::fprintf(f, "{\"benchmark\":\"round_trip\",\"count\":%d,\"runs\":%d,\"rows\":[", count,
                 runs);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      std::fprintf(f,
                   "%s{\"transport\":\"%s\",\"path\":\"%s\",\"failed\":%d,\"requester_switches\":"
                   "%.3f,\"responder_switches\":%.3f,\"requester_cpu_us\":%.2f,"
                   "\"responder_cpu_us\":%.2f,\"latency\":%s}",
                   i == 0 ? "" : ",", rows[i].transport.c_str(), rows[i].path.c_str(),
                   rows[i].failed, rows[i].requester_switches, rows[i].responder_switches,
                   rows[i].requester_cpu_us, rows[i].responder_cpu_us,
                   bench::to_json(rows[i].latency).c_str());
    }
    std::fprintf(f, "],\"ratios\":[%s],\"service_overhead\":[", ratios_json.c_str());
    for (std::size_t i = 0; i < overheads.size(); ++i) {
      const Overhead& o = overheads[i];
      std::fprintf(f,
                   "%s{\"command\":\"%s\",\"commands\":%zu,\"request_to_frame\":%s,"
                   "\"frame_to_echo\":%s,"
                   "\"echo_to_reply_write\":%s,\"echo_to_reply_written\":%s,"
                   "\"reply_write_call\":%s}",
                   i == 0 ? "" : ",", command_name(o.command), o.commands,
                   bench::to_json(o.request_to_frame).c_str(),
                   bench::to_json(o.frame_to_echo).c_str(),
                   bench::to_json(o.echo_to_reply_write).c_str(),
                   bench::to_json(o.echo_to_reply_written).c_str(),
                   bench::to_json(o.reply_write_call).c_str());
    }
    std::fprintf(f, "]}\n");
    std::fclose(f);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Command round trip through dh3 against a raw Fast DDS ping-pong; service overhead"};
  bench::CommonOptions common;
  bench::add_common_options(app, common);
  int count = 10'000;
  int runs = 1;
  bool udp_only = false;
  bool hop = false;
  Command command = Command::read;
  app.add_option("--count", count, "Timed commands per row")->capture_default_str();
  app.add_option("--runs", runs, "Repeat the round trips; print each run and the median ratios")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--command", command, "(client role) read or write")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, Command>{{"read", Command::read}, {"write", Command::write}}));
  app.add_flag("--hop", hop, "(responder role) reply from a second thread");
  app.add_flag("--udp-only", udp_only, "(child roles) UDP only, no shared memory");
  CLI11_PARSE(app, argc, argv);
  auto& [json_path, role, domain, service] = common;
  spdlog::set_level(spdlog::level::warn);
  if (role == "responder") return run_responder(domain, udp_only, hop);
  if (role == "client") {
    const Measured measured = client_round_trips(domain, service, udp_only, count, command, 0);
    std::printf("done %zu ok, %d failed\n", measured.micros.size(), measured.failed);
    return 0;
  }
  return run_benchmark(count, runs, json_path);
}
