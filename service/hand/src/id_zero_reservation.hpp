#pragma once
// Loop thread only: the bus loop tells it what went out and asks it when.
// Pure: it is told the time of each frame and probe; it reads no clock.
//
// Pacing across senders. Each driver paces its own frames
// (SchedulerOptions::frame_spacing()). A frame to CAN ID 0 reaches every hand
// on the bus, so it waits until no hand, and no discovery probe, had a frame
// within the spacing, and every hand and the scan wait the spacing after it.
// While it waits, the others are held past its slot, so it cannot starve
// behind hands that keep polling. This class keeps the times; the scheduler
// holds the drivers where it says.

#include <cstdint>
#include <optional>

#include "dh3/base/clock.hpp"

namespace dh3::hand {

class IdZeroReservation {
 public:
  /// `spacing`: what the scheduler keeps between two frames to one hand.
  explicit IdZeroReservation(Duration spacing) : spacing_(spacing) {}

  /// Called every pass before sending. `waiting`: ID 0 has a command frame
  /// ready; `earliest`: when its own pacing lets it go (or the pass's time if
  /// later). Returns the slot when one is newly reserved: ID 0 is held until
  /// it and every other hand until slot + spacing. nullopt when nothing
  /// waits (any reservation is dropped) or the slot is already reserved.
  [[nodiscard]] std::optional<TimePoint> reserve(bool waiting, TimePoint earliest);
  /// Whether ID 0 may send at `now`: the spacing since the last frame to any
  /// other hand or probe has passed. If not (something went out after the
  /// slot was reserved, a delayed send), the reservation is dropped so that
  /// the next pass reserves again.
  [[nodiscard]] bool may_send(TimePoint now);
  /// A frame to `can_id` left the bus at `left`. For ID 0 the reservation is
  /// used up; the scheduler holds every other hand until left + spacing.
  void frame_sent(std::uint8_t can_id, TimePoint left);
  /// A discovery probe left at `left`.
  void probe_sent(TimePoint left);
  /// Probes wait while a frame to ID 0 waits, and the spacing after one.
  [[nodiscard]] TimePoint probes_allowed_at() const;
  /// When the spacing since the last frame to any hand but ID 0 (or probe) has passed.
  [[nodiscard]] TimePoint others_clear_at() const { return others_last_ + spacing_; }
  /// The reserved slot, if a frame to ID 0 waits for one.
  [[nodiscard]] std::optional<TimePoint> slot() const { return slot_; }

 private:
  Duration spacing_;
  /// The latest frame to a hand other than ID 0, or probe (epoch if none).
  TimePoint others_last_{};
  std::optional<TimePoint> id_zero_last_;
  std::optional<TimePoint> slot_;
};

}  // namespace dh3::hand
