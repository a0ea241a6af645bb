#pragma once
// The calls between call() or group_call() and their end: by request_seq,
// each with its deadline and the incarnation its request was written to; the
// queue of requests for the io thread; the io thread's next wake. Single and
// group calls (dh3/group.hpp) take the same path; a group call's request goes
// on the group topic, and only once its service's group endpoints matched.
//
// Not thread-safe: ClientCore keeps it under its state mutex (a service's loss
// ends its calls with its statuses). Knows no DDS, nor the clock: told the time.

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "dh3/address.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/group.hpp"
#include "dh3/types.hpp"

namespace dh3::detail {

class PendingCalls {
 public:
  using Clock = std::chrono::steady_clock;
  using Done = std::function<void(Reply)>;
  using GroupDone = std::function<void(GroupReply)>;
  /// A call's end, to run once no lock is held.
  using Completion = std::pair<Done, Reply>;
  /// A request as it is written: on the command topic or the group topic.
  using Outgoing = std::variant<msg::CommandRequest, msg::GroupRequest>;

  /// A group call's own part.
  struct Group {
    msg::GroupRequest request;
    std::string what;  ///< "GROUP MOVE of 2 hand(s)"
    GroupDone done;    ///< takes its reply; every other end goes through Call::done
  };

  struct Call {
    HandAddress hand;             ///< a group call's: its service only
    msg::CommandRequest request;  ///< a single call's
    std::optional<Group> group;   ///< set for a group call
    Clock::time_point deadline;
    std::chrono::milliseconds timeout{};
    /// Ends the call with the client's own code (and a single call with its
    /// reply); a group call's adapts the Reply to a GroupReply.
    Done done;
    std::string sent_to;  ///< the incarnation it was written to; empty: not yet written

    /// SET_CAN_ID or SET_BAUD_RATE: written on the admin request topic.
    [[nodiscard]] bool administrative() const;
    /// "MOVE for cell/bus0/1", "GROUP MOVE of 2 hand(s)".
    [[nodiscard]] std::string what() const;
  };
  /// The calls whose deadline passed, and the next deadline (max if none).
  struct Expiry {
    std::vector<Call> expired;
    Clock::time_point next = Clock::time_point::max();
  };

  /// The next request_seq (single and group calls share them).
  std::uint64_t next_seq() { return ++last_seq_; }
  /// Files a call under its request_seq. True if its deadline comes before the
  /// io thread's next wake (the io thread must be woken to see it).
  bool add(std::uint64_t seq, Call call);
  [[nodiscard]] Call* find(std::uint64_t seq);
  std::optional<Call> take(std::uint64_t seq);

  /// The calls for `service` not yet written go to `incarnation`, queued for
  /// the io thread; group calls only when `group_ready` (its group endpoints
  /// matched). True if any was.
  bool assign(const std::string& service, const std::string& incarnation, bool group_ready = false,
              bool admin_ready = false);
  /// A request to write, and the incarnation it is written to
  /// (contract::addressed_to: no other serves it).
  struct Write {
    std::uint64_t seq = 0;
    Outgoing request;
    std::string to;
  };
  /// What writing call `seq` writes.
  [[nodiscard]] static Write write_of(std::uint64_t seq, const Call& call);
  /// Queues a call already assigned for the io thread.
  void queue(std::uint64_t seq) { to_write_.push_back(seq); }
  [[nodiscard]] bool queue_empty() const { return to_write_.empty(); }
  /// The next queued request of a call still pending; calls ended meanwhile
  /// are skipped (never sent, so a command the caller was told failed does not
  /// run after all).
  std::optional<Write> next_to_write();

  /// Ends the calls written to `incarnation` SERVICE_LOST, saying `why`.
  std::vector<Completion> end_sent_to(const std::string& incarnation, const std::string& why);
  /// Ends every call with `reply` and empties the queue.
  std::vector<Completion> end_all(const Reply& reply);
  /// Takes the calls whose deadline is at or before `now`; the next deadline
  /// becomes the io thread's next wake.
  Expiry expire(Clock::time_point now);
  /// The io thread sleeps until `wake_at` unless woken.
  void set_next_wake(Clock::time_point wake_at) { next_wake_ = wake_at; }

  /// Requests being written now, by callers or the io thread (close() waits for them).
  void begin_write() { ++writes_in_flight_; }
  void end_write() { --writes_in_flight_; }
  [[nodiscard]] int writes_in_flight() const { return writes_in_flight_; }

  /// Why a call ended at its deadline. `service_alive`: its service was found.
  /// `seen`, if not empty, ends a NO_SERVICE message: what discovery showed
  /// of the service (ServiceTracker::sightings).
  [[nodiscard]] static Reply expired_reply(const Call& call, bool service_alive, int domain,
                                           const std::string& seen = {});
  /// Says in each NO_REPLY among `expired` (single calls) whether the
  /// services' request readers acknowledged every request written, so a
  /// caller knows whether the service may have run it. `acknowledged` asks
  /// the request writer (without the client's mutex), only if there is one.
  static void tell_acknowledgment(std::vector<Completion>& expired,
                                  const std::function<bool()>& acknowledged);

 private:
  std::uint64_t last_seq_ = 0;
  std::map<std::uint64_t, Call> calls_;
  std::deque<std::uint64_t> to_write_;  ///< request_seqs for the io thread
  Clock::time_point next_wake_ = Clock::time_point::max();
  int writes_in_flight_ = 0;
};

}  // namespace dh3::detail
