#pragma once
// Whether this process has read everything its UDP sockets received: the
// evidence LapseJudge needs (lapse_judge.hpp) that a lapse is the owner's
// silence and not this process's own lag. Linux: the process's descriptors
// from /proc/self/fd, each UDP socket's next datagram from SIOCINQ.
//
// Thread-safe. Every client of a process shares the looks: its participants
// share its CPUs, and 32 clients looking at once must not cost 32 times.

#include <functional>

#include "lapse_judge.hpp"

namespace dh3::detail {

class ReceiveQueues {
 public:
  /// One look now: current if no UDP socket of this process holds a datagram,
  /// behind if one does, unknown if the descriptors cannot be listed.
  [[nodiscard]] static ReceiveState look_once();
  /// What LapseJudge takes: a look, tried again twice a few milliseconds
  /// apart while a datagram waits (a receive thread that keeps up reads one
  /// in microseconds: one empty look is the evidence, a datagram that has
  /// just arrived is not lag), and reused by every caller for that long.
  [[nodiscard]] static ReceiveState look();
  /// What a client whose participant receives as `udp_only` says
  /// (contract::Participant::receives_over_udp_only) looks with: look(), or
  /// unknown for any other transport (shared memory has no queue to ask).
  [[nodiscard]] static std::function<ReceiveState()> looker(bool udp_only);
};

}  // namespace dh3::detail
