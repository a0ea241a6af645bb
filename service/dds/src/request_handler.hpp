#pragma once
// Command requests: each one validated (request_validation.hpp), run (a hand
// command, a scan or a lease change) and answered with exactly one reply.
//
// Threading: handle() on the request listener's thread, one at a time (the
// Service's dispatch lock); completions on the bus loops; writes under no lock of its own.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "client_rate.hpp"
#include "client_share.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/dds/service.hpp"
#include "dh3/hand/bus_scheduler.hpp"
#include "hand_directory.hpp"
#include "lease_table.hpp"
#include "reply_sink.hpp"
#include "request_validation.hpp"

namespace dh3::dds {

class ExpiryTimer;
class StatusPublisher;

/// Who sent a request: the participant that wrote the sample (its id,
/// contract::client_id_for of the sample's writer) and how people see it
/// (participant_names.hpp). Leases are bound to the id; a request's own
/// client_id field only addresses the reply.
struct Caller {
  std::string id;
  std::string shown_as;
};

/// The topic a request came on: command requests, or administrative ones
/// (dh3/contract/admin_commands.hpp), whose topic DDS Security's permissions
/// grant to admin identities only.
enum class RequestTopic : std::uint8_t { commands, admin };

/// What a reply echoes from its request.
struct ReplyHeader {
  std::string client_id;
  std::uint64_t request_seq = 0;
  msg::HandAddress hand;
  msg::CommandType command = msg::INITIALIZE;
};

[[nodiscard]] msg::CommandReply make_reply(const ReplyHeader& header, msg::ResultCode code,
                                           std::string message = {});

/// The buses' schedulers, by bus index (the Service owns them).
using Schedulers = std::vector<std::unique_ptr<hand::BusScheduler>>;

class RequestHandler {
 public:
  /// The parts a request uses; each outlives the handler.
  struct Parts {
    const ServiceOptions& options;
    const HandDirectory& directory;
    LeaseTable& leases;
    const Schedulers& schedulers;
    StatusPublisher& statuses;
    ReplySink& replies;
    ExpiryTimer& timer;
    /// Bounds each caller's commands and scans in flight (BUSY beyond).
    ClientShare& share;
  };
  explicit RequestHandler(Parts parts) : parts_(parts) {}
  RequestHandler(const RequestHandler&) = delete;
  RequestHandler& operator=(const RequestHandler&) = delete;

  /// Answers the request of `caller` that came on `topic` (`stopping`:
  /// CANCELLED); `request` is reused by the caller, its strings may be moved from.
  void handle(msg::CommandRequest& request, const Caller& caller, bool stopping,
              RequestTopic topic = RequestTopic::commands);
  /// Under DDS Security's access control the topic a request came on says
  /// what the writer's identity may do: administrative commands are then
  /// taken only from the admin request topic. Set before requests are taken.
  void set_access_control(bool on) { access_control_ = on; }
  /// Bounds each caller's requests a second (BUSY beyond); none: no bound.
  /// Set before requests are taken; `rate` outlives the handler.
  void set_rate(ClientRate* rate) { rate_ = rate; }
  /// Answers every scan still pending CANCELLED (stop, after the buses stopped).
  void cancel_scans();

 private:
  struct PendingScan {
    ReplyHeader header;
    ClientShare::Ticket ticket;  ///< freed when it is answered
    std::atomic<bool> answered{false};
  };

  void submit_command(const ValidRequest& valid, const Caller& caller, ReplyHeader header);
  void start_scan(const ValidRequest& valid, const Caller& caller, ReplyHeader header);
  /// A slot of the caller's share for a request that will be in flight, or
  /// nullopt when it was answered BUSY instead.
  std::optional<ClientShare::Ticket> take_slot(const Caller& caller, const ReplyHeader& header);
  void finish_scan(const std::shared_ptr<PendingScan>& scan, msg::ResultCode code,
                   const std::vector<std::uint8_t>& found, std::string message);
  void handle_lease(const ValidRequest& valid, const Caller& caller, const ReplyHeader& header);

  /// What an administrative command that came on `topic` may do.
  [[nodiscard]] AdminAccess admin_access(RequestTopic topic) const;

  Parts parts_;
  bool access_control_ = false;
  ClientRate* rate_ = nullptr;
  std::mutex scans_mutex_;
  std::vector<std::shared_ptr<PendingScan>> scans_;  ///< under scans_mutex_
};

}  // namespace dh3::dds
