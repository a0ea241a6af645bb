#pragma once
// Which hands a bus has and the state each last published: the one record of
// both. The bus's scheduler owns it and its loop writes it (a hand configured,
// a hand discovered, a driver publishing); any thread may read it, so the DDS
// side asks it instead of keeping its own list or copy.

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "dh3/hand/hand_types.hpp"

namespace dh3::hand {

struct HandConfig {
  std::uint8_t can_id = 1;
  std::string name;
};

class HandRoster {
 public:
  /// The configured hands (ID 0 and repeated IDs are ignored; the first name wins).
  explicit HandRoster(const std::vector<HandConfig>& configured = {}) {
    for (const HandConfig& hand : configured) {
      if (hand.can_id == 0 || known_[hand.can_id].load(std::memory_order_relaxed)) continue;
      names_[hand.can_id] = hand.name;
      known_[hand.can_id].store(true, std::memory_order_release);
    }
  }
  HandRoster(const HandRoster&) = delete;
  HandRoster& operator=(const HandRoster&) = delete;

  // ---- any thread; lock-free, so a request never waits for the bus loop ----

  [[nodiscard]] bool knows(std::uint8_t can_id) const {
    return can_id != 0 && known_[can_id].load(std::memory_order_acquire);
  }
  /// The configured name, empty if none (names are fixed at construction).
  [[nodiscard]] const std::string& name(std::uint8_t can_id) const { return names_[can_id]; }
  /// Every known hand, by CAN ID.
  [[nodiscard]] std::vector<HandConfig> hands() const {
    std::vector<HandConfig> out;
    for (std::size_t id = 1; id < known_.size(); ++id) {
      if (known_[id].load(std::memory_order_acquire)) {
        out.push_back({static_cast<std::uint8_t>(id), names_[id]});
      }
    }
    return out;
  }

  /// Records a hand that was found; true if it was not known before.
  bool add(std::uint8_t can_id) {
    return can_id != 0 && !known_[can_id].exchange(true, std::memory_order_acq_rel);
  }

  // ---- published states (hand_roster.cpp) ----------------------------------

  /// True if `state` differs from the hand's last published state in a field a
  /// user sees (or the hand never published).
  [[nodiscard]] bool differs_from_published(const HandState& state) const;
  /// Records `state` as the hand's published state (bus loop).
  void publish(const HandState& state);
  /// Every hand's last published state, by CAN ID.
  [[nodiscard]] std::vector<HandState> published() const;

 private:
  std::array<std::atomic<bool>, 256> known_{};
  std::array<std::string, 256> names_{};

  mutable std::mutex published_mutex_;
  std::array<std::optional<HandState>, 256> published_{};  ///< under published_mutex_
};

}  // namespace dh3::hand
