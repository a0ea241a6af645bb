#pragma once
// Each client's rate of requests: at most `per_second` a second, in bursts
// of up to that many (a bucket of that many requests per client, refilled
// evenly over each second). ClientShare bounds what a client has in flight;
// this bounds what it may send, answered or not: requests refused at once
// (validation, leases, a client over its share) cost the service a reply
// each, so a client writing them as fast as it can would take the request
// reader's time from the others. A request beyond the rate is answered BUSY
// at once, saying why.
//
// Clients are the participants that wrote the requests (Caller::id). A
// group request is one request of its caller, in the same bucket as the
// caller's single ones: otherwise groups would be a way around the rate.
//
// Thread-safe: admit() on the request and group listeners' threads,
// forget() on the participant listener's. Knows no Fast DDS; time comes
// from a Clock.

#include <cstdint>
#include <map>
#include <mutex>
#include <string>

#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"

namespace dh3::dds {

class ClientRate {
 public:
  /// `per_second` 0: no limit.
  ClientRate(const Clock& clock, std::uint32_t per_second) : clock_(clock), rate_(per_second) {}
  ClientRate(const ClientRate&) = delete;
  ClientRate& operator=(const ClientRate&) = delete;

  /// One more request of participant `caller_id` now, or the BUSY message
  /// that names the client (`shown_as`) and the rate.
  Result<void, std::string> admit(const std::string& caller_id, const std::string& shown_as);
  /// The participant left: its bucket goes (a new one starts full).
  void forget(const std::string& caller_id);
  /// Requests refused for their rate since the start.
  [[nodiscard]] std::uint64_t refused() const;

 private:
  struct Bucket {
    double requests = 0;  ///< what the client may still send at once
    TimePoint filled;     ///< when `requests` was last brought up to date
    bool warned = false;  ///< logged once while over its rate
  };

  const Clock& clock_;
  const std::uint32_t rate_;
  mutable std::mutex mutex_;
  std::map<std::string, Bucket> buckets_;  ///< by caller id, under mutex_
  std::uint64_t refused_ = 0;              ///< under mutex_
};

}  // namespace dh3::dds
