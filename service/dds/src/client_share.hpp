#pragma once
// Each client's share of the work the service takes on: how many of its
// requests may be in flight at once (taken and not yet answered: a command
// waiting in a hand's queue or running, a scan). One KEEP_ALL reader takes
// every client's requests, so without a share one client's flood would fill
// the hands' queues and the scan list and leave another client's single
// command BUSY or waiting behind it. A request beyond its client's share is
// answered BUSY at once, saying why.
//
// Clients are the participants that wrote the requests (Caller::id), never a
// request's client_id field, which any participant may fill in.
//
// Thread-safe: admit() on the request listener's thread, tickets released on
// the bus loops. Knows no Fast DDS.

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "dh3/base/result.hpp"

namespace dh3::dds {

class ClientShare {
 public:
  /// One request in flight; its slot is free again when the last copy of
  /// the ticket is gone (copies may ride in completions).
  class Ticket {
   public:
    Ticket() = default;

   private:
    friend class ClientShare;
    struct Slot;
    explicit Ticket(std::shared_ptr<const Slot> slot) : slot_(std::move(slot)) {}
    std::shared_ptr<const Slot> slot_;
  };

  /// The most requests of one client in flight. A client waits for its
  /// replies: dh3ctl has one request in flight, a program one or two per hand
  /// it drives, a group command is one request; a cell has a few dozen hands.
  static constexpr std::size_t kMaxInFlight = 64;

  explicit ClientShare(std::size_t max_in_flight = kMaxInFlight) : max_(max_in_flight) {}
  ClientShare(const ClientShare&) = delete;
  ClientShare& operator=(const ClientShare&) = delete;
  /// Every ticket must be gone before the share is.
  ~ClientShare() = default;

  /// A ticket for one more request of participant `caller_id`, or the BUSY
  /// message that names the client (`shown_as`) and the bound.
  Result<Ticket, std::string> admit(const std::string& caller_id, const std::string& shown_as);
  [[nodiscard]] std::size_t in_flight(const std::string& caller_id) const;
  [[nodiscard]] std::size_t max_in_flight() const { return max_; }
  /// Requests refused for their client's share since the start.
  [[nodiscard]] std::uint64_t refused() const;

 private:
  struct Client {
    std::size_t in_flight = 0;
    bool warned = false;  ///< logged once while over its share
  };
  void release(const std::string& caller_id);

  const std::size_t max_;
  mutable std::mutex mutex_;
  std::map<std::string, Client> clients_;  ///< those with requests in flight, by caller id
  std::uint64_t refused_ = 0;              ///< under mutex_
};

}  // namespace dh3::dds
