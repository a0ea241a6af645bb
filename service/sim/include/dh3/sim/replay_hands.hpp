#pragma once
// The hands of a recording (ReplayScript), answering as they did: a request is
// answered with the reply recorded for the same register, in the recorded
// order, after the recorded latency, and the frames a hand sent unasked come
// at their recorded offset after the write that began their epoch.
//
// A write moves the hand to its next epoch, so the reads after it get what
// was recorded after it, however many reads the replay made before: a
// service polling at another pace cannot shift a "caught" into the time of an
// earlier move. Within an epoch, when a register's replies are used up, the
// last one is repeated (the hand stays as it was last seen); a register not yet
// answered in the recording gets the first reply recorded for it anywhere, and
// one never answered gets none, as the recorded hand gave none. A write whose
// recorded replies are used up is echoed. Pure: it is told the time.

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/protocol/codec.hpp"
#include "dh3/sim/replay_script.hpp"
#include "dh3/sim/sim_hand.hpp"

namespace dh3::sim {

class ReplayHands {
 public:
  /// Epoch 0's unasked frames count from `start`.
  ReplayHands(const ReplayScript& script, TimePoint start);

  /// The recorded hands' CAN IDs, ascending (ID 0 if it answered, too).
  [[nodiscard]] std::vector<std::uint8_t> ids() const;

  /// As HandSet::deliver(): a request to the hand it addresses; its reply goes
  /// to `replies`, unasked frames now due to `unsolicited`. Returns the number
  /// of hands it reached (0 or 1).
  std::size_t deliver(const protocol::Message& request, TimePoint now,
                      std::vector<Outgoing>& replies, std::vector<Outgoing>& unsolicited);
  /// Appends every hand's unasked frames due by `now`.
  void advance_all(TimePoint now, std::vector<Outgoing>& out);
  [[nodiscard]] std::optional<TimePoint> next_unsolicited_at() const;

 private:
  struct Hand {
    const RecordedHand* recorded = nullptr;
    std::size_t epoch = 0;
    /// How many of the epoch's replies each register has used.
    std::map<std::uint16_t, std::size_t> used;
    std::map<std::uint16_t, std::size_t> writes_used;
    /// The reply a register gave last (repeated when its replies run out).
    std::map<std::uint16_t, RecordedReply> last;
    std::vector<Outgoing> unasked;  ///< scheduled, due order
  };

  void begin_epoch(Hand& hand, std::size_t epoch, TimePoint now);
  [[nodiscard]] static std::optional<RecordedReply> read_reply(Hand& hand, std::uint16_t reg);
  [[nodiscard]] static std::optional<RecordedReply> first_reply(const RecordedHand& hand,
                                                                std::uint16_t reg);
  static void take_due(Hand& hand, TimePoint now, std::vector<Outgoing>& out);

  std::map<std::uint8_t, Hand> hands_;
};

}  // namespace dh3::sim
