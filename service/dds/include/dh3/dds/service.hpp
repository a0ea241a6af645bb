#pragma once
// dh3-service's DDS side: one participant that publishes every hand's status,
// the hands' events and the service's description, and answers command
// requests by handing them to the bus schedulers. The only part of the service
// that knows Fast DDS; this header keeps it out of its users.
//
// Threads: each bus's scheduler runs its own loop; status, event and reply
// samples are written from there. Requests are validated on the DDS listener
// thread and submitted straight to the scheduler (never blocking). A timer
// thread ends expired leases.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/contract/participant_options.hpp"
#include "dh3/dds/request_trace_seam.hpp"
#include "dh3/hand/bus_scheduler.hpp"

namespace dh3::dds {

/// One bus the service runs: the open bus, the hands expected on it (empty:
/// discover them) and the scheduler's tuning.
struct BusSetup {
  std::string name;
  std::unique_ptr<bus::Bus> bus;
  std::vector<hand::HandConfig> hands;
  hand::SchedulerOptions scheduler;
  /// What a standby saw of the hands before it took the bus over (empty:
  /// nothing known; the hands are read afresh).
  std::vector<hand::HandState> warm;
};

struct ServiceOptions {
  std::string name = "dh3";  ///< answers requests whose hand.service is this
  /// Domain, transports, discovery servers, XML profile and DDS Security of
  /// the service's participant (its name is "dh3-service " + name).
  contract::ParticipantOptions participant = default_participant();
  bool allow_admin = false;  ///< SET_CAN_ID and SET_BAUD_RATE are refused unless set
  /// Each client's requests a second, in bursts of as many (client_rate.hpp);
  /// beyond it BUSY. 0: no limit.
  std::uint32_t client_rate_limit = 1000;
  std::string version;       ///< published in the service info
  std::string host;          ///< published in the service info
  /// A hand's status whose values did not change, only their read time (the
  /// hand read again at rest), is republished at most this often; any
  /// change goes out at once. Every watcher receives each sample, so at
  /// rest this is what a hand costs the network: with the idle poll's 500
  /// ms, 2 samples/s per hand to each watcher would go out instead of 0.2.
  /// Zero: every idle read is published.
  Duration status_refresh = std::chrono::seconds(5);
  /// How long create() listens for another live service of this name before
  /// it claims the name (docs/failover.md); unset: contract::kStartClaimWindow,
  /// longer than the owner lease (a service killed just before is seen dead)
  /// and than discovery takes.
  std::optional<Duration> claim_window;
  /// Runs once in create(), after the name was claimed and before any bus
  /// is used, with the buses: those to serve, or why the service must not
  /// serve them (create() fails with it, and the claim is withdrawn). The
  /// program's bus fence (dh3-service: nobody else drives them). Unset: the
  /// buses as given. Not run at a takeover (the standby fenced them).
  std::function<Result<std::vector<BusSetup>, std::string>(std::vector<BusSetup>)> before_serving;
  /// The least epoch the claim takes: a standby taking over claims above the
  /// owner it replaces, whose claim its new participant never receives.
  std::uint64_t epoch_floor = 0;
  /// Runs once, on an internal thread, when a service of this name that
  /// outranks this one appears (two services met after a partition healed):
  /// from then on this one takes no request; the program should stop.
  std::function<void(const std::string& why)> on_lost_ownership;
  /// How long stop() waits for subscribers to acknowledge the last samples.
  Duration shutdown_ack_timeout = std::chrono::seconds(2);
  /// Test seam (request_trace_seam.hpp): called at each TracePoint of every
  /// request, on the thread that is there (must be quick). Unset, the
  /// default: nothing but the emptiness test.
  RequestTracer test_seam_tracer;

  /// The service's identity in the test PKI unless told otherwise.
  static contract::ParticipantOptions default_participant() {
    contract::ParticipantOptions participant;
    participant.security_identity = "service";
    return participant;
  }
};

class StandbyPresence;

class Service {
 public:
  /// Creates the participant, claims the service's name (listening for
  /// options.claim_window first), then the topics and writers; nothing else
  /// runs yet. Fails with a message if DDS cannot be set up (e.g. a bad
  /// interface address) or if the name is already served on the domain (the
  /// message names the other service's host and process).
  [[nodiscard]] static Result<std::unique_ptr<Service>, std::string> create(
      ServiceOptions options, std::vector<BusSetup> buses, const Clock& clock);
  /// A standby's takeover: the service is made on the standby's participant,
  /// whose claim turns active at once (no listening window), with an epoch
  /// above every claim seen and at least options.epoch_floor.
  [[nodiscard]] static Result<std::unique_ptr<Service>, std::string> take_over(
      ServiceOptions options, std::vector<BusSetup> buses, const Clock& clock,
      StandbyPresence& standby);
  ~Service();
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  /// Publishes the service info and every configured hand's status, starts the
  /// buses' loops and begins answering requests. Fails, saying which, if the
  /// request reader cannot be created (e.g. DDS Security permissions that do
  /// not allow it): a service that cannot take requests must not run. Then
  /// stop() (or the destructor) ends what was started.
  [[nodiscard]] Result<void, std::string> start();
  /// Orderly stop: new requests are answered CANCELLED, the buses stop (their
  /// pending commands end CANCELLED), every hand is published offline, and the
  /// last samples are given shutdown_ack_timeout to be acknowledged. Idempotent.
  void stop();

  /// Every bus's counters and its hands' (for the metrics endpoint). Any
  /// thread, until the Service is destroyed.
  [[nodiscard]] std::vector<hand::BusMetrics> metrics() const;
  /// Requests answered BUSY at once and held replies dropped, since the start.
  struct Refusals {
    std::uint64_t busy_in_flight = 0;  ///< beyond a client's share (client_share.hpp)
    std::uint64_t busy_rate = 0;       ///< beyond a client's rate (client_rate.hpp)
    std::uint64_t held_replies_dropped = 0;
  };
  /// Any thread, until the Service is destroyed.
  [[nodiscard]] Refusals refusals() const;

 private:
  class Impl;
  explicit Service(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dh3::dds
