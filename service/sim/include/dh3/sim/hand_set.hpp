#pragma once
// The simulated hands on one line (a CAN bus or a transfer box), addressed by
// the CAN ID each answers on. Shared by the in-process SimBus and dh3-sim.
// Not thread-safe: its owner serializes access.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "dh3/sim/sim_hand.hpp"

namespace dh3::sim {

class HandSet {
 public:
  /// Adds a hand; a hand already answering on that ID is replaced (two hands
  /// with one ID on a bus cannot be told apart). Returns true if one was replaced.
  bool add(const SimHandOptions& options, TimePoint now);
  /// Removes the hand answering on `id`; false if there is none.
  bool remove(std::uint8_t id);
  [[nodiscard]] SimHand* find(std::uint8_t id);
  [[nodiscard]] std::size_t size() const { return count_; }
  /// IDs in ascending order.
  [[nodiscard]] std::vector<std::uint8_t> ids() const;

  /// Hands a request to the hand it addresses, or to every hand for ID 0, and
  /// appends their replies to `replies` and any unsolicited frame that came due
  /// meanwhile to `unsolicited` (may be the same vector). Returns the number of
  /// hands it reached.
  std::size_t deliver(const protocol::Message& request, TimePoint now,
                      std::vector<Outgoing>& replies, std::vector<Outgoing>& unsolicited);

  /// Advances every hand to `now` and appends their unsolicited frames to `out`.
  void advance_all(TimePoint now, std::vector<Outgoing>& out);
  /// The earliest next_unsolicited_at() of all hands.
  [[nodiscard]] std::optional<TimePoint> next_unsolicited_at() const;

  /// Runs `action` on the hand answering on `id` (false if none). If the hand's
  /// ID changed (reboot after a CAN ID write), it is filed under the new ID,
  /// replacing a hand already there. `new_id`, if given, receives its ID after.
  bool with_hand(std::uint8_t id, const std::function<void(SimHand&)>& action,
                 std::uint8_t* new_id = nullptr);

 private:
  std::array<std::unique_ptr<SimHand>, 256> hands_{};
  std::size_t count_ = 0;
};

}  // namespace dh3::sim
