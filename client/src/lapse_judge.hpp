#pragma once
// When the calls in flight to a service whose owner liveliness lapsed end
// SERVICE_LOST: with the service's loss (contract::kOwnerLapseConfirm after
// Fast DDS reported the lapse) if this process has read everything it was
// sent; only once it has caught up if it had fallen behind.
//
// Why this tells a dead service from a client that stalled itself: Fast DDS
// 2.9 reports a lapse from its event thread, a lease after the last assertion
// its receive threads processed. A process that starves itself (32
// participants in one process on 2 cores under a sanitizer) leaves a live
// owner's assertions unread in its sockets meanwhile, and reading them
// overturns the lapse. Each UDP receive thread reads its socket in order and
// processes a datagram before it reads the next (UDPChannelResource), and
// processing an assertion overturns the lapse on that thread
// (LivelinessManager::assert_liveliness calls the reader's listener). So if,
// after the lapse was reported, no datagram waits unread in any UDP socket of
// this process, every assertion that reached it was read, all but the last
// of each socket processed; a live owner sends one every 100 ms, so a lapse
// still standing then is the owner's silence (killed, frozen or cut off),
// not this process's lag.
//
// A look that finds datagrams waiting means this process is behind: the lapse
// is judged only once looks have found the queues empty for kCaughtUpSpan. A
// process that was behind may have lost assertions to a full socket buffer;
// a live owner's next two reach it within that span and are read. There is
// no limit while it stays behind: its calls end at their deadline (NO_REPLY,
// which says as much). Where the queues cannot be seen (a transport other
// than UDP, no /proc), the calls end once the lapse stood
// contract::kOwnerLapseCallConfirm, as the only evidence left is time.
//
// Pure: the caller makes the looks (receive_queues.hpp) and gives the times.

#include <chrono>
#include <cstdint>
#include <optional>

namespace dh3::detail {

/// What one look at this process's UDP receive queues found.
enum class ReceiveState : std::uint8_t {
  current,  ///< no datagram waited unread: all that arrived had been read
  behind,   ///< datagrams waited: the process had not kept up
  unknown,  ///< the queues cannot be seen
};

class LapseJudge {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;
  /// How often to look while the process is behind or catching up.
  static constexpr std::chrono::milliseconds kLookAgain{50};
  /// How long a process that was behind must be seen current before a lapse
  /// that still stands ends its calls: two assertion periods and a margin.
  static constexpr std::chrono::milliseconds kCaughtUpSpan{250};

  /// A lapse Fast DDS reported at `reported`.
  explicit LapseJudge(TimePoint reported) : reported_(reported) {}

  /// What a look made at `at` found (the lapse stood until after it).
  void take(TimePoint at, ReceiveState found);
  /// When to look next; max() once a look found the queues cannot be seen.
  [[nodiscard]] TimePoint next_look() const;
  /// The calls in flight may end at `now`.
  [[nodiscard]] bool calls_end(TimePoint now) const;
  /// When calls_end() becomes true without another look: max() unless the
  /// queues cannot be seen.
  [[nodiscard]] TimePoint blind_end() const;

 private:
  TimePoint reported_;
  bool blind_ = false;        ///< a look found the queues cannot be seen
  bool was_behind_ = false;   ///< some look found the process behind
  std::optional<TimePoint> last_look_;
  /// The first of the looks since the last behind one, all current; empty
  /// if the last look found the process behind.
  std::optional<TimePoint> current_since_;
};

}  // namespace dh3::detail
