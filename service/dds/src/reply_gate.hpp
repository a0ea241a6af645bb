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
// A participant that writes requests and never reads replies would make the
// gate hold every reply for the whole hold limit, so the gate holds at most
// HoldCaps: beyond a client's cap its own oldest held reply is dropped, beyond
// the total the oldest of the client that holds the most. The oldest, because
// it is the one its client is likeliest to have given up on, and the newest
// are the ones a client that is merely slow to match still waits for; the one
// that holds the most, so that a flood never pushes out another client's few.
//
// One gate per reply writer, for its own matches: ReplyGate<msg::CommandReply>
// and ReplyGate<msg::GroupReply> (any IDL reply with a client_id()).
//
// Thread-safe: replies come from bus threads and the request listener;
// participants and matches from Fast DDS's listener threads; expiry from the
// service's timer. Knows no Fast DDS entity: the caller writes what it returns.

#include <cstddef>
#include <cstdint>
#include <deque>
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

/// How many replies one gate holds at most. A real client holds what it sent
/// before its reply reader matched: one request, or one per hand it drives
/// at start, far below the per-client cap; a cell of a few dozen clients stays
/// far below the total. A held reply is a few hundred bytes, so the total
/// bounds a gate to about a megabyte.
/// Each at least 1.
struct HoldCaps {
  std::size_t per_client = 256;
  std::size_t total = 4096;
};

/// A held reply that the caps pushed out, never to be written.
struct DroppedReply {
  std::string client_id;
  std::uint64_t request_seq = 0;
  std::size_t client_drops = 0;  ///< the client's drops so far, this one included
  bool over_total = false;       ///< the gate's total cap, not the client's own
};

struct Admission {
  GateOutcome outcome = GateOutcome::pass;
  std::optional<DroppedReply> dropped;  ///< what holding this reply pushed out
};

template <typename Reply>
class ReplyGate {
 public:
  ReplyGate(const Clock& clock, Duration hold_limit, HoldCaps caps = {})
      : clock_(clock), hold_limit_(hold_limit), caps_(caps) {}

  /// A participant with this client_id (its GUID prefix in hex) was discovered.
  void participant_joined(const std::string& client_id);
  /// It left; its held replies are dropped (nobody is left to read them).
  /// Returns how many.
  std::size_t participant_left(const std::string& client_id);
  /// The reply writer matched (`matched`) or lost a reader of `client_id`'s
  /// participant. On a match, returns the replies held for it, oldest first,
  /// for the caller to write.
  std::vector<Reply> reader_matched(const std::string& client_id, bool matched);
  /// Whether `reply` may be written now; if held, it is moved in, and an
  /// older held reply may be dropped for it (the caps).
  Admission admit(Reply& reply);
  /// Held replies older than hold_limit, oldest first, for the caller to write.
  std::vector<Reply> expire();
  /// Every held reply, oldest first (the service is stopping: written as they are).
  std::vector<Reply> take_all();
  /// When the oldest held reply reaches hold_limit, nullopt if none is held.
  [[nodiscard]] std::optional<TimePoint> next_expiry() const;
  [[nodiscard]] std::size_t held() const;
  /// Replies the caps dropped: of one client (while it is known), and of all.
  [[nodiscard]] std::size_t dropped(const std::string& client_id) const;
  [[nodiscard]] std::size_t dropped() const;

 private:
  struct Held {
    TimePoint since;
    Reply reply;
  };
  struct Client {
    int readers = 0;
    std::deque<Held> held;
    std::size_t dropped = 0;
  };

  /// The held replies before `due`, oldest first, taken out.
  std::vector<Reply> take_locked(TimePoint due);
  using Clients = std::map<std::string, Client>;

  /// Makes room for one more reply of `client` within the caps.
  std::optional<DroppedReply> make_room_locked(typename Clients::iterator client);

  const Clock& clock_;
  const Duration hold_limit_;
  const HoldCaps caps_;
  mutable std::mutex mutex_;
  Clients clients_;          ///< known participants, by client_id
  std::size_t held_ = 0;     ///< over every client
  std::size_t dropped_ = 0;  ///< over every client, ever
};

// Defined in reply_gate.cpp for these two.
extern template class ReplyGate<msg::CommandReply>;
extern template class ReplyGate<msg::GroupReply>;

}  // namespace dh3::dds
