#pragma once
// A simulated DH-3 hand that behaves as the protocol document says: echo on
// write, value on read, initialization that takes time and may announce its
// end, motion toward a target at a set speed, an object that stops the fingers,
// drops, rotation, the CAN ID / baud / version registers, and injectable faults.
// Pure model: it is told the time, it never reads a clock or does I/O.

#include <cstdint>
#include <optional>
#include <vector>

#include "common/clock.hpp"
#include "protocol/codec.hpp"

namespace dh3::sim {

struct SimHandOptions {
  std::uint8_t id = 1;
  /// Finger speed in percent of the stroke per second.
  double position_speed = 200.0;
  /// Rotation speed in percent of 90 degrees per second.
  double rotation_speed = 200.0;
  /// How long initialization takes.
  Duration init_time = std::chrono::milliseconds(300);
  /// An object between the fingers at this position (0-100): closing below it
  /// stops there with status "caught".
  std::optional<std::int32_t> object_position;
  /// An obstacle that blocks rotation at this value (0-100).
  std::optional<std::int32_t> rotation_obstacle;
  /// Firmware version register value; the document's example 00 02 01 04.
  std::int32_t firmware_version = 0x04010200;
  std::int32_t baud_index = 0;
  /// Time between a request and the reply.
  Duration reply_delay = Duration::zero();
};

/// A reply or an unsolicited frame, due at `due`.
struct Outgoing {
  TimePoint due;
  protocol::Message message;
};

class SimHand {
 public:
  SimHand(SimHandOptions options, TimePoint now);

  /// Handles one request addressed to this hand (or to ID 0 for the CAN ID
  /// register) and returns what the hand sends back: nothing when muted.
  [[nodiscard]] std::vector<Outgoing> handle(const protocol::Message& request, TimePoint now);

  /// Moves the model to `now` and returns unsolicited frames that became due
  /// (the initialization-finished frame when 0x0801 is enabled).
  [[nodiscard]] std::vector<Outgoing> advance(TimePoint now);

  // Fault and world injection.
  void set_muted(bool muted);
  void set_reply_delay(Duration delay);
  /// The next `count` replies carry a flipped byte in the data field.
  void corrupt_next_replies(int count);
  void place_object(std::optional<std::int32_t> position);
  /// The caught object slips out: the grip status leaves 3 with no command.
  void drop_object();

  // The model's true state, for tests.
  [[nodiscard]] std::uint8_t id() const;
  [[nodiscard]] bool initialized() const;
  [[nodiscard]] double position() const;
  [[nodiscard]] double rotation() const;
  [[nodiscard]] protocol::GripStatus grip_status() const;
  [[nodiscard]] protocol::GripStatus rotation_status() const;
  [[nodiscard]] std::int32_t closing_force() const;
  [[nodiscard]] std::int32_t opening_force() const;
  /// Requests received, including ignored ones (muted, out of range).
  [[nodiscard]] std::uint64_t requests_seen() const;

 private:
  struct State;
  // Implementation chooses the members; see sim_hand.cpp.
  SimHandOptions options_;
  bool muted_ = false;
  int corrupt_remaining_ = 0;
  bool init_feedback_ = false;
  bool initialized_ = false;
  std::optional<TimePoint> init_done_at_;
  double position_ = 100.0;
  std::int32_t position_target_ = 100;
  double rotation_ = 0.0;
  std::int32_t rotation_target_ = 0;
  protocol::GripStatus grip_status_ = protocol::GripStatus::moving;
  protocol::GripStatus rotation_status_ = protocol::GripStatus::moving;
  std::int32_t closing_force_ = 50;
  std::int32_t opening_force_ = 50;
  std::int32_t can_id_ = 1;
  TimePoint last_update_{};
  std::uint64_t requests_seen_ = 0;
};

}  // namespace dh3::sim
