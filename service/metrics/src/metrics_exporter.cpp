#include "dh3/metrics/metrics_exporter.hpp"

#include <arpa/inet.h>
#include <prometheus/client_metric.h>
#include <prometheus/collectable.h>
#include <prometheus/exposer.h>
#include <prometheus/metric_family.h>
#include <prometheus/text_serializer.h>

#include <array>
#include <exception>
#include <initializer_list>
#include <limits>
#include <tuple>

#include "dh3/base/host_port.hpp"

namespace dh3::metrics {
namespace {

using prometheus::ClientMetric;
using prometheus::MetricFamily;
using prometheus::MetricType;

MetricFamily family(std::string name, std::string help, MetricType type) {
  MetricFamily out;
  out.name = std::move(name);
  out.help = std::move(help);
  out.type = type;
  return out;
}

ClientMetric& add(MetricFamily& family, std::vector<ClientMetric::Label> labels) {
  ClientMetric& metric = family.metric.emplace_back();
  metric.label = std::move(labels);
  return metric;
}

void add_counter(MetricFamily& family, std::vector<ClientMetric::Label> labels,
                 std::uint64_t value) {
  add(family, std::move(labels)).counter.value = static_cast<double>(value);
}

void add_gauge(MetricFamily& family, std::vector<ClientMetric::Label> labels, double value) {
  add(family, std::move(labels)).gauge.value = value;
}

std::vector<ClientMetric::Label> hand_labels(const std::string& bus, const hand::HandMetrics& h) {
  return {{"bus", bus}, {"hand", std::to_string(h.can_id)}, {"name", h.name}};
}

/// A hand-layer histogram (counts per bound, then above the last) as
/// Prometheus' cumulative buckets; the count is the +Inf bucket.
template <typename Histogram, std::size_t N>
void add_histogram(MetricFamily& family, std::vector<ClientMetric::Label> labels,
                   const Histogram& histogram, const std::array<Duration, N>& bounds) {
  static_assert(std::tuple_size_v<decltype(histogram.counts)> == N + 1);
  ClientMetric::Histogram& out = add(family, std::move(labels)).histogram;
  std::uint64_t cumulative = 0;
  for (std::size_t i = 0; i < N; ++i) {
    cumulative += histogram.counts[i];
    out.bucket.push_back({cumulative, std::chrono::duration<double>(bounds[i]).count()});
  }
  cumulative += histogram.counts.back();
  out.bucket.push_back({cumulative, std::numeric_limits<double>::infinity()});
  out.sample_count = cumulative;
  out.sample_sum = histogram.sum_seconds;
}

/// Moves the families that have samples into `out`.
void take_filled(std::initializer_list<MetricFamily*> families, std::vector<MetricFamily>& out) {
  for (MetricFamily* f : families) {
    if (!f->metric.empty()) out.push_back(std::move(*f));
  }
}

/// The per-hand series.
struct HandFamilies {
  MetricFamily commands =
      family("dh3_hand_commands_total", "Commands that reached the hand layer, by type and result",
             MetricType::Counter);
  MetricFamily timeouts =
      family("dh3_hand_timeouts_total", "Frames to the hand not answered within their deadline",
             MetricType::Counter);
  MetricFamily retries =
      family("dh3_hand_retries_total", "Frames re-sent after a timeout", MetricType::Counter);
  MetricFamily round_trip =
      family("dh3_hand_round_trip_seconds",
             "Time from a frame sent to the hand to its matching reply", MetricType::Histogram);
  MetricFamily online =
      family("dh3_hand_online", "1 while the hand answers, 0 otherwise", MetricType::Gauge);

  void add(const std::string& bus, const hand::HandMetrics& h) {
    for (const hand::CommandTally& tally : h.commands) {
      auto labels = hand_labels(bus, h);
      labels.push_back({"type", std::string(command_type_name(tally.kind, tally.reg))});
      labels.push_back({"result", std::string(result_name(tally.error))});
      add_counter(commands, std::move(labels), tally.count);
    }
    add_counter(timeouts, hand_labels(bus, h), h.timeouts);
    add_counter(retries, hand_labels(bus, h), h.retries);
    add_histogram(round_trip, hand_labels(bus, h), h.round_trip, hand::kRoundTripBuckets);
    if (h.online) add_gauge(online, hand_labels(bus, h), *h.online ? 1.0 : 0.0);
  }
  void take(std::vector<MetricFamily>& out) {
    take_filled({&commands, &timeouts, &retries, &round_trip, &online}, out);
  }
};

/// The per-bus series every backend has.
struct BusFamilies {
  MetricFamily sent = family("dh3_bus_frames_sent_total", "CAN frames sent", MetricType::Counter);
  MetricFamily received =
      family("dh3_bus_frames_received_total", "CAN frames received", MetricType::Counter);
  MetricFamily errors = family("dh3_bus_errors_total",
                               "Frames nobody waited for (kind=unexpected_frame) and sends or "
                               "receives the bus refused on a live link (kind=bus_error)",
                               MetricType::Counter);
  MetricFamily reconnects =
      family("dh3_bus_reconnects_total", "Link down to up transitions", MetricType::Counter);
  MetricFamily link_up = family("dh3_bus_link_up", "1 while the link is up", MetricType::Gauge);
  MetricFamily load = family("dh3_bus_load_percent",
                             "Frames sent and received over the last 5 s, at 111 bits each (no "
                             "stuff bits), in percent of the bus's bit rate",
                             MetricType::Gauge);

  void add(const hand::BusMetrics& bus) {
    const std::vector<ClientMetric::Label> bus_label{{"bus", bus.bus}};
    add_counter(sent, bus_label, bus.counters.frames_sent);
    add_counter(received, bus_label, bus.counters.frames_received);
    add_counter(errors, {{"bus", bus.bus}, {"kind", "unexpected_frame"}},
                bus.counters.unexpected_frames);
    add_counter(errors, {{"bus", bus.bus}, {"kind", "bus_error"}}, bus.counters.bus_errors);
    add_counter(reconnects, bus_label, bus.counters.reconnects);
    add_gauge(link_up, bus_label, bus.link_up ? 1.0 : 0.0);
    if (bus.line_load_percent) add_gauge(load, bus_label, *bus.line_load_percent);
  }
  void take(std::vector<MetricFamily>& out) {
    take_filled({&sent, &received, &errors, &reconnects, &link_up, &load}, out);
  }
};

/// How long things take on each bus (hand::BusLatency).
struct LatencyFamilies {
  MetricFamily command_to_frame =
      family("dh3_bus_command_to_frame_seconds",
             "Time from a command taken by the hand layer to its first frame on the bus (the wait "
             "for the hand's turn: its command interval, the line budget, the command before it)",
             MetricType::Histogram);
  MetricFamily frame_to_reply =
      family("dh3_bus_frame_to_reply_seconds",
             "Time from any frame sent to a hand (command or poll) to its matching reply",
             MetricType::Histogram);
  MetricFamily command_to_reply =
      family("dh3_bus_command_to_reply_seconds",
             "Time from a command taken by the hand layer to its result handed back (a grasp or "
             "release: once the motion ended and where the fingers stopped was read)",
             MetricType::Histogram);
  MetricFamily sample_age =
      family("dh3_bus_status_sample_age_seconds",
             "Age of each status sample when it is published: time since the hand's reply "
             "it reflects",
             MetricType::Histogram);

  void add(const hand::BusMetrics& bus) {
    const std::vector<ClientMetric::Label> bus_label{{"bus", bus.bus}};
    add_histogram(command_to_frame, bus_label, bus.latency.command_to_frame, hand::kLatencyBuckets);
    add_histogram(frame_to_reply, bus_label, bus.latency.frame_to_reply, hand::kLatencyBuckets);
    add_histogram(command_to_reply, bus_label, bus.latency.command_to_reply, hand::kLatencyBuckets);
    add_histogram(sample_age, bus_label, bus.latency.sample_age, hand::kLatencyBuckets);
  }
  void take(std::vector<MetricFamily>& out) {
    take_filled({&command_to_frame, &frame_to_reply, &command_to_reply, &sample_age}, out);
  }
};

/// What only a backend on a CAN controller (SocketCAN) sees.
struct ControllerFamilies {
  MetricFamily error_frames =
      family("dh3_bus_error_frames_total", "Error frames the CAN controller reported, by kind",
             MetricType::Counter);
  MetricFamily bus_off = family(
      "dh3_bus_off", "1 while the CAN controller is bus-off (the link is down)", MetricType::Gauge);
  MetricFamily overflow =
      family("dh3_bus_rx_overflow_drops_total",
             "Frames the kernel dropped because the receive queue was full", MetricType::Counter);
  MetricFamily ignored = family("dh3_bus_frames_ignored_total",
                                "Frames no DH-3 hand sends that reached the service (the kernel "
                                "filter keeps most of them out unseen)",
                                MetricType::Counter);

  void add(const std::string& bus, const bus::BusDiagnostics& seen) {
    if (!seen.sees_controller) return;
    const std::vector<ClientMetric::Label> bus_label{{"bus", bus}};
    for (std::size_t i = 0; i < bus::kErrorFrameKinds; ++i) {
      const auto kind = static_cast<bus::ErrorFrameKind>(i);
      add_counter(error_frames, {{"bus", bus}, {"kind", std::string(to_string(kind))}},
                  seen.error_frames[i]);
    }
    add_gauge(bus_off, bus_label, seen.bus_off ? 1.0 : 0.0);
    add_counter(overflow, bus_label, seen.rx_overflow_drops);
    add_counter(ignored, bus_label, seen.frames_ignored);
  }
  void take(std::vector<MetricFamily>& out) {
    take_filled({&error_frames, &bus_off, &overflow, &ignored}, out);
  }
};

/// The flight recorder's, for buses that are recorded.
struct RecorderFamilies {
  MetricFamily frames = family("dh3_recorder_frames_total",
                               "Frames the flight recorder wrote to its files", MetricType::Counter);
  MetricFamily dropped = family("dh3_recorder_dropped_total",
                                "Frames the flight recorder lost: its queue was full (the writer "
                                "fell behind the bus) or a file could not be written",
                                MetricType::Counter);
  MetricFamily bytes =
      family("dh3_recorder_bytes_total", "Bytes the flight recorder wrote", MetricType::Counter);
  MetricFamily files = family("dh3_recorder_files_total",
                              "Files the flight recorder opened (the first and each rotation)",
                              MetricType::Counter);
  MetricFamily errors =
      family("dh3_recorder_write_errors_total",
             "Times a recording file could not be opened or written", MetricType::Counter);
  MetricFamily stopped =
      family("dh3_recorder_stopped",
             "1 while a write error (a full disk) keeps the flight recorder from recording; it "
             "deletes no recording meanwhile and records again once a write succeeds",
             MetricType::Gauge);

  void add(const std::string& bus, const bus::BusDiagnostics& seen) {
    if (!seen.recorder) return;
    const std::vector<ClientMetric::Label> bus_label{{"bus", bus}};
    add_counter(frames, bus_label, seen.recorder->frames_recorded);
    add_counter(dropped, bus_label, seen.recorder->frames_dropped);
    add_counter(bytes, bus_label, seen.recorder->bytes_written);
    add_counter(files, bus_label, seen.recorder->files_opened);
    add_counter(errors, bus_label, seen.recorder->write_errors);
    add_gauge(stopped, bus_label, seen.recorder->stopped ? 1.0 : 0.0);
  }
  void take(std::vector<MetricFamily>& out) {
    take_filled({&frames, &dropped, &bytes, &files, &errors, &stopped}, out);
  }
};

/// The service's refusals (RequestFigures).
void add_request_families(const RequestFigures& requests, std::vector<MetricFamily>& out) {
  MetricFamily busy = family("dh3_requests_busy_total",
                             "Requests answered BUSY by the service at once, by reason: in_flight "
                             "(the client had 64 in flight), rate (beyond client_rate_limit)",
                             MetricType::Counter);
  add_counter(busy, {{"reason", "in_flight"}}, requests.busy_in_flight);
  add_counter(busy, {{"reason", "rate"}}, requests.busy_rate);
  out.push_back(std::move(busy));
  MetricFamily dropped = family("dh3_held_replies_dropped_total",
                                "Replies held for a client whose reply reader had not matched and "
                                "dropped unwritten by the hold caps",
                                MetricType::Counter);
  add_counter(dropped, {}, requests.held_replies_dropped);
  out.push_back(std::move(dropped));
}

std::vector<MetricFamily> families(const std::vector<hand::BusMetrics>& buses) {
  HandFamilies hands;
  BusFamilies bus_families;
  ControllerFamilies controllers;
  RecorderFamilies recorders;
  LatencyFamilies latency;
  for (const hand::BusMetrics& bus : buses) {
    bus_families.add(bus);
    latency.add(bus);
    controllers.add(bus.bus, bus.diagnostics);
    recorders.add(bus.bus, bus.diagnostics);
    for (const hand::HandMetrics& h : bus.hands) hands.add(bus.bus, h);
  }
  std::vector<MetricFamily> out;
  hands.take(out);
  bus_families.take(out);
  latency.take(out);
  controllers.take(out);
  recorders.take(out);
  return out;
}

class Collector final : public prometheus::Collectable {
 public:
  Collector(Source source, RequestSource requests)
      : source_(std::move(source)), requests_(std::move(requests)) {}
  std::vector<MetricFamily> Collect() const override {
    auto out = families(source_());
    if (requests_) add_request_families(requests_(), out);
    return out;
  }

 private:
  Source source_;
  RequestSource requests_;
};

/// HOST:PORT with an IP address literal (IPv6 in brackets); port 0 is any free port.
Result<HostPort, std::string> parse_listen_address(std::string_view address) {
  const auto bad = [&](const std::string& why) {
    return fail("metrics address '" + std::string(address) + "': " + why +
                " (expected HOST:PORT: an IPv4 address or a bracketed IPv6 address and a port "
                "in 0-65535, e.g. 127.0.0.1:9464, 0.0.0.0:9464 or [::1]:9464)");
  };
  HostPortRules listening;
  listening.port_zero = true;
  auto parsed = parse_host_port(address, listening);
  if (!parsed) return bad(parsed.error());
  in6_addr literal{};
  const int family = parsed->bracketed ? AF_INET6 : AF_INET;
  if (inet_pton(family, parsed->host.c_str(), &literal) != 1) {
    // Appended: GCC 12 warns falsely (-Wrestrict) about "literal" + std::string at -O3.
    return bad(std::string("'").append(parsed->written_host()).append("' is not an IP address"));
  }
  return parsed;
}

}  // namespace

std::string render(const std::vector<hand::BusMetrics>& buses,
                   const std::optional<RequestFigures>& requests) {
  auto out = families(buses);
  if (requests) add_request_families(*requests, out);
  return prometheus::TextSerializer().Serialize(out);
}

std::string_view command_type_name(hand::CommandKind kind, protocol::Register reg) {
  using hand::CommandKind;
  switch (kind) {
    case CommandKind::initialize:
      return "INITIALIZE";
    case CommandKind::move_to:
      return "MOVE";
    case CommandKind::set_closing_force:
      return "SET_CLOSING_FORCE";
    case CommandKind::set_opening_force:
      return "SET_OPENING_FORCE";
    case CommandKind::rotate_to:
      return "ROTATE";
    case CommandKind::read_register:
      return "READ_REGISTER";
    case CommandKind::write_register:
      if (reg == protocol::reg::kCanId) return "SET_CAN_ID";
      if (reg == protocol::reg::kBaudRate) return "SET_BAUD_RATE";
      if (reg == protocol::reg::kInitFeedback) return "ENABLE_INIT_FEEDBACK";
      return "WRITE_REGISTER";
    case CommandKind::grasp:
      return "GRASP";
    case CommandKind::release:
      return "RELEASE";
    case CommandKind::stop:
      return "STOP";
  }
  return "UNKNOWN_COMMAND";
}

std::string_view result_name(std::optional<hand::CommandError> error) {
  if (!error) return "OK";
  using hand::CommandError;
  switch (*error) {
    case CommandError::invalid_argument:
      return "INVALID_ARGUMENT";
    case CommandError::unknown_hand:
      return "UNKNOWN_HAND";
    case CommandError::timeout:
      return "TIMEOUT";
    case CommandError::bus_down:
      return "BUS_DOWN";
    case CommandError::busy:
      return "BUSY";
    case CommandError::not_initialized:
      return "NOT_INITIALIZED";
    case CommandError::cancelled:
      return "CANCELLED";
    case CommandError::failed:
      return "FAILED";
  }
  return "FAILED";
}

Result<void, std::string> check_listen_address(std::string_view address) {
  auto parsed = parse_listen_address(address);
  if (!parsed) return fail(std::move(parsed).error());
  return {};
}

std::string exposure_warning(std::string_view address) {
  const auto parsed = parse_listen_address(address);
  if (!parsed || is_loopback_host(parsed->host)) return {};
  return "metrics served on " + std::string(address) +
         ", beyond this machine: whoever reaches that port reads every bus's and hand's name, "
         "state and counters (no token, no Host check); serve them on 127.0.0.1 and let a local "
         "Prometheus or a proxy reach them, or limit the port in the firewall";
}

class Exporter::Impl {
 public:
  std::shared_ptr<Collector> collector;
  std::unique_ptr<prometheus::Exposer> exposer;
  std::string address;
};

Result<std::unique_ptr<Exporter>, std::string> Exporter::start(const std::string& address,
                                                               Source source,
                                                               RequestSource requests) {
  auto parsed = parse_listen_address(address);
  if (!parsed) return fail(parsed.error());
  auto impl = std::make_unique<Impl>();
  impl->collector = std::make_shared<Collector>(std::move(source), std::move(requests));
  try {
    // One serving thread: scrapes are rare and each only copies counters.
    impl->exposer = std::make_unique<prometheus::Exposer>(address, 1);
  } catch (const std::exception& error) {
    return fail("cannot serve metrics on " + address + ": " + error.what() +
                " (is the port in use, or the address not one of this host's?)");
  }
  const auto ports = impl->exposer->GetListeningPorts();
  if (ports.empty()) return fail("cannot serve metrics on " + address + ": no port was bound");
  impl->exposer->RegisterCollectable(impl->collector);
  impl->address = parsed->written_host() + ":" + std::to_string(ports.front());
  return std::unique_ptr<Exporter>(new Exporter(std::move(impl)));
}

Exporter::Exporter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Exporter::~Exporter() = default;

const std::string& Exporter::address() const {
  return impl_->address;
}

}  // namespace dh3::metrics
