#pragma once
// dh3-service's Prometheus endpoint: on every scrape of /metrics it takes a
// snapshot of the hand layer's counters (BusScheduler::metrics()) and renders
// it; the data path only counts. Depends on the hand layer, not on DDS.
//
// Series (labels bus; per hand also hand = CAN ID and name = configured name):
//   dh3_hand_commands_total{type,result}  commands by the contract's names
//   dh3_hand_timeouts_total, dh3_hand_retries_total
//   dh3_hand_round_trip_seconds           histogram, frame sent -> reply
//   dh3_hand_online                       1 online, 0 not
//   dh3_bus_frames_sent_total, dh3_bus_frames_received_total
//   dh3_bus_errors_total{kind}            unexpected_frame | bus_error
//   dh3_bus_reconnects_total, dh3_bus_link_up
//   dh3_bus_load_percent                  only for buses that know their bit rate
//   dh3_bus_command_to_frame_seconds      histogram, command taken -> first frame
//   dh3_bus_frame_to_reply_seconds        histogram, any frame -> its reply
//   dh3_bus_command_to_reply_seconds      histogram, command taken -> result
//   dh3_bus_status_sample_age_seconds     histogram, a sample's age when published
// and for buses on a CAN controller (SocketCAN) only:
//   dh3_bus_error_frames_total{kind}      error frames by bus::ErrorFrameKind name
//   dh3_bus_off                           1 while the controller is bus-off
//   dh3_bus_rx_overflow_drops_total       frames the kernel dropped, receive queue full
//   dh3_bus_frames_ignored_total          frames no DH-3 hand sends that got through
// and for buses with a flight recorder only:
//   dh3_recorder_frames_total, dh3_recorder_dropped_total, dh3_recorder_bytes_total,
//   dh3_recorder_files_total, dh3_recorder_write_errors_total, dh3_recorder_stopped
// and for the service's requests (no bus label; RequestFigures):
//   dh3_requests_busy_total{reason}       answered BUSY at once: in_flight | rate
//   dh3_held_replies_dropped_total        held replies the hold caps dropped

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/result.hpp"
#include "dh3/hand/hand_metrics.hpp"

namespace dh3::metrics {

/// Where the figures come from; called on the exporter's threads per scrape.
using Source = std::function<std::vector<hand::BusMetrics>()>;

/// What the service answered BUSY or dropped rather than serve, since it
/// started (docs/security.md, "Floods"): dh3_requests_busy_total{reason} and
/// dh3_held_replies_dropped_total.
struct RequestFigures {
  std::uint64_t busy_in_flight = 0;        ///< a client had too many requests in flight
  std::uint64_t busy_rate = 0;             ///< a client sent more than its rate
  std::uint64_t held_replies_dropped = 0;  ///< replies the hold caps dropped unwritten
};
using RequestSource = std::function<RequestFigures()>;

/// The Prometheus text exposition of `buses` (and `requests`), as /metrics serves it.
[[nodiscard]] std::string render(const std::vector<hand::BusMetrics>& buses,
                                 const std::optional<RequestFigures>& requests = std::nullopt);

/// The contract's name of a command type: "MOVE", "SET_CAN_ID", ...
/// ("WRITE_REGISTER" for register writes the contract has no command for).
[[nodiscard]] std::string_view command_type_name(hand::CommandKind kind, protocol::Register reg);
/// The contract's name of a result: "OK", "TIMEOUT", ...
[[nodiscard]] std::string_view result_name(std::optional<hand::CommandError> error);

/// Fine if `address` is a listening address the exporter takes
/// ("IPv4:PORT" or "[IPv6]:PORT", port 0-65535, 0 = any free port),
/// otherwise fails with what is wrong with it.
[[nodiscard]] Result<void, std::string> check_listen_address(std::string_view address);

/// What serving metrics on `address` (as check_listen_address takes it) lets
/// others read, for a warning at start; empty where only this machine reaches
/// it (a loopback address). The endpoint has no token and checks no Host
/// header: beyond loopback, whoever reaches the port reads it.
[[nodiscard]] std::string exposure_warning(std::string_view address);

class Exporter {
 public:
  /// Listens on `address` and serves /metrics until destroyed. Fails with a
  /// message if the address is malformed or cannot be bound.
  [[nodiscard]] static Result<std::unique_ptr<Exporter>, std::string> start(
      const std::string& address, Source source, RequestSource requests = {});
  ~Exporter();
  Exporter(const Exporter&) = delete;
  Exporter& operator=(const Exporter&) = delete;

  /// The address actually bound, with the port chosen when 0 was asked for.
  [[nodiscard]] const std::string& address() const;

 private:
  class Impl;
  explicit Exporter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dh3::metrics
