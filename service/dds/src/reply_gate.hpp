#pragma once
// Replies wait for their reader. A client may send a request as soon as its
// request writer has matched the service, before the service's reply writer
// has matched the client's reply reader. The reply writer keeps its last
// kStreamDepth replies for such a late reader (TRANSIENT_LOCAL), but when more
// replies than that are written before the reader matches, as in a burst of
// clients started together, the client's own reply is pushed out and it is
// never answered (2 of 128 dh3ctl started at once were). So a reply to a client
// whose participant the service knows, and none of whose reply readers the
// writer has matched yet, is held until one matches or `hold_limit` passes
// (then it is written anyway: the writer's history is the fallback). Every
// other reply passes at once: a client whose client_id names no participant
// (another vendor's client may use any id) is answered as before.
//
// One gate per reply writer, for its own matches: ReplyGate<msg::CommandReply>
// and ReplyGate<msg::GroupReply> (any IDL reply with a client_id()).
//
// Thread-safe: replies come from bus threads and the request listener;
// participants and matches from Fast DDS's listener threads; expiry from the
// service's timer. Knows no Fast DDS entity: the caller writes what it returns.

#include <cstddef>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/contract/dh3.h"

namespace dh3::dds {

enum class GateOutcome : std::uint8_t {
  pass,  ///< write it now
  held,  ///< taken in; released by reader_matched() or expire()
};

template <typename Reply>
class ReplyGate {
 public:
  ReplyGate(const Clock& clock, Duration hold_limit) : clock_(clock), hold_limit_(hold_limit) {}

  /// A participant with this client_id (its GUID prefix in hex) was discovered.
  void participant_joined(const std::string& client_id);
  /// It left; its held replies are dropped (nobody is left to read them).
  /// Returns how many.
  std::size_t participant_left(const std::string& client_id);
  /// The reply writer matched (`matched`) or lost a reader of `client_id`'s
  /// participant. On a match, returns the replies held for it, oldest first,
  /// for the caller to write.
  std::vector<Reply> reader_matched(const std::string& client_id, bool matched);
  /// Whether `reply` may be written now; if held, it is moved in.
  GateOutcome admit(Reply& reply);
  /// Held replies older than hold_limit, oldest first, for the caller to write.
  std::vector<Reply> expire();
  /// Every held reply, oldest first (the service is stopping: written as they are).
  std::vector<Reply> take_all();
  /// When the oldest held reply reaches hold_limit, nullopt if none is held.
  [[nodiscard]] std::optional<TimePoint> next_expiry() const;
  [[nodiscard]] std::size_t held() const;

 private:
  struct Held {
    TimePoint since;
    Reply reply;
  };
  struct Client {
    int readers = 0;
    std::vector<Held> held;
  };

  /// The held replies before `due`, oldest first, taken out.
  std::vector<Reply> take_locked(TimePoint due);

  const Clock& clock_;
  const Duration hold_limit_;
  mutable std::mutex mutex_;
  std::map<std::string, Client> clients_;  ///< known participants, by client_id
};

// Defined in reply_gate.cpp for these two.
extern template class ReplyGate<msg::CommandReply>;
extern template class ReplyGate<msg::GroupReply>;

}  // namespace dh3::dds
