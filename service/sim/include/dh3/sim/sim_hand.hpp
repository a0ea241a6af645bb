#pragma once
// A simulated DH-3 hand that behaves as the protocol document says: echo on
// write, value on read, initialization that takes time and may announce its
// end, motion toward a target at a set speed, an object that stops the fingers,
// drops, rotation, the CAN ID / baud / version registers, and injectable faults.
// Pure model: it is told the time, it never reads a clock or does I/O.
//
// How the model answers, register by register (the reply keeps the request's
// hand ID, register and read/write byte; its reserve byte is always 0):
//
// - Reads return the register's value in the data field. Position and rotation
//   read the fingers' current place, rounded to whole percent, also while moving.
//   Status reads (0x0F01, 0x0F02) put the status in the data field, never in the
//   reserve byte (docs/protocol-notes.md reading 2).
// - Writes that are applied are echoed byte for byte.
// - Writes that cannot be applied are answered, not ignored, with the value the
//   register keeps: an out-of-range value (force outside 20-100, position or
//   rotation outside 0-100, CAN ID outside 1-255, baud index outside 0-5) or a
//   write to a read-only register (0x0F01, 0x0F02, 0x1301). The hand received
//   the frame, so it acknowledges it as the document promises, and a client that
//   compares the echo with its request sees at once that the value was refused.
//   This is also exactly what the document's "read CAN ID with ID 0" example
//   shows: a write of 0 to 0x1201 (out of range) answered with the ID, 2.
// - 0x0801: a write enables initialization feedback whatever its data (the
//   document writes 0) and is answered with 0xA5, the register's new value; a
//   read answers 0xA5 when enabled, 0 otherwise. There is no documented way to
//   turn it off; a reboot clears it.
// - 0x0802: a write starts (or restarts) initialization and is echoed; a read
//   answers 1 once initialization finished, 0 otherwise. Initialization takes
//   `init_time`; with feedback enabled the hand then sends, unsolicited,
//   `08 02 00 00 00 00 00 00` (the document's frame). Afterwards the fingers are
//   fully open (100), the rotation at 0 and both statuses 0 ("default").
// - Position and rotation writes before initialization has finished (never
//   initialized, or initializing) are echoed but not executed: the motors are
//   not calibrated, so the hand does not move, its status stays 0. The service
//   refuses such commands itself; the sim only must not pretend to move.
// - A position or rotation write starts a motion at `position_speed` /
//   `rotation_speed` (status 0 while moving, 2 on arrival). A new target
//   interrupts the running motion.
// - Object: closing (target below the object's position) from at or above the
//   object stops the fingers at the object's position with grip status 3. The
//   object stays where it is when the fingers open again, like a part held in a
//   fixture, so every closing catches it until it is dropped or moved.
// - Drop: the object disappears; if the fingers held it they continue toward
//   their target (status 0, then 2) although no command was sent.
// - Rotation obstacle: a rotation whose path crosses the obstacle stops there
//   with rotation status 3.
// - 0x1201 / 0x1401 writes store the new setting and are answered after the
//   longer `store_delay` (the document: settings reply only once stored). Both
//   take effect only after reboot(): until then the hand keeps answering on its
//   old ID. A read returns the stored value. The baud rate has no effect on the
//   simulated line.
// - ID 0 addresses any hand, but only for the CAN ID register (docs/protocol-notes.md
//   reading 10); the reply carries ID 0, as in the document.
// - Registers the document does not list get no reply (the hand does not
//   understand them).
//
// Faults: a muted hand ignores every request and sends nothing (also no
// initialization frame), as if its CAN transceiver were cut; its motion goes on.
// Corruption flips the low data byte (XOR 0xFF) of the next frames it sends.
//
// Injections (set_muted, place_object, drop_object, ...) take effect at the time
// of the last handle()/advance() call: callers advance the hand to `now` first.

#include <cstdint>
#include <optional>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/protocol/codec.hpp"

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
  /// Extra time before the reply to a CAN ID or baud rate write (storing it).
  Duration store_delay = std::chrono::milliseconds(50);
  /// Forces after power-on (0x0502 closing, 0x0503 opening), 20-100 %.
  std::int32_t closing_force = 50;
  std::int32_t opening_force = 50;
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

  /// When advance() will next have an unsolicited frame to return (the end of
  /// a running initialization with feedback enabled), nullopt if none is coming.
  [[nodiscard]] std::optional<TimePoint> next_unsolicited_at() const;

  /// Power cycle: the stored CAN ID and baud rate take effect, the hand is no
  /// longer initialized, feedback and forces return to their power-on values.
  /// The fingers stay where they are. Injected faults stay.
  void reboot(TimePoint now);

  // Fault and world injection.
  void set_muted(bool muted);
  void set_reply_delay(Duration delay);
  /// The next `count` replies carry a flipped byte in the data field.
  void corrupt_next_replies(int count);
  void place_object(std::optional<std::int32_t> position);
  /// The caught object slips out: the grip status leaves 3 with no command.
  void drop_object();
  void place_rotation_obstacle(std::optional<std::int32_t> position);

  // The model's true state, for tests.
  /// The ID the hand answers on (changes only on reboot()).
  [[nodiscard]] std::uint8_t id() const;
  /// The ID stored by the last CAN ID write, active after reboot().
  [[nodiscard]] std::uint8_t stored_id() const;
  /// The baud index as stored (what a read of 0x1401 answers).
  [[nodiscard]] std::int32_t baud_index() const;
  [[nodiscard]] bool initialized() const;
  [[nodiscard]] bool init_feedback_enabled() const;
  [[nodiscard]] bool muted() const;
  [[nodiscard]] double position() const;
  [[nodiscard]] double rotation() const;
  [[nodiscard]] protocol::GripStatus grip_status() const;
  [[nodiscard]] protocol::GripStatus rotation_status() const;
  /// When the grip status took its current value: the exact moment the fingers
  /// touched the object or reached their target (worked out from their speed,
  /// not when the model was next advanced), or of the drop, command or reboot
  /// that changed it. Lets a benchmark time how long the news takes to arrive.
  [[nodiscard]] TimePoint grip_status_since() const;
  [[nodiscard]] std::int32_t closing_force() const;
  [[nodiscard]] std::int32_t opening_force() const;
  [[nodiscard]] std::optional<std::int32_t> object_position() const;
  /// Requests received, including ignored ones (muted, out of range).
  [[nodiscard]] std::uint64_t requests_seen() const;

 private:
  /// One motor: fingers (stopped by the object) or rotation (by the obstacle).
  struct Axis {
    double position = 0.0;
    std::int32_t target = 0;
    double speed = 0.0;
    bool moving = false;
    protocol::GripStatus status = protocol::GripStatus::moving;
    /// Seconds into the last step at which it stopped (caught or arrived).
    double stopped_after = 0.0;
  };

  void update(TimePoint now);
  /// Records when the grip status changed, if it did since the last call.
  void note_grip_change(TimePoint at);
  void finish_initialization();
  void step_fingers(double seconds);
  void step_rotation(double seconds);
  static void step_axis(Axis& axis, double seconds, std::optional<double> stop);
  [[nodiscard]] std::optional<double> finger_stop() const;
  [[nodiscard]] std::optional<double> rotation_stop() const;
  void start_motion(Axis& axis, std::int32_t target);
  /// The reply's data and whether the write was stored (longer delay), or
  /// nullopt for registers the hand does not know.
  struct Answer {
    std::int32_t data = 0;
    bool stored_setting = false;
  };
  [[nodiscard]] std::optional<Answer> answer(const protocol::Message& request, TimePoint now);
  [[nodiscard]] protocol::Message maybe_corrupt(protocol::Message message);

  SimHandOptions options_;
  bool muted_ = false;
  int corrupt_remaining_ = 0;
  bool init_feedback_ = false;
  bool initialized_ = false;
  std::optional<TimePoint> init_done_at_;
  Axis fingers_;
  Axis rotation_;
  std::optional<std::int32_t> object_;
  std::optional<std::int32_t> obstacle_;
  int rotation_obstacle_side_ = 0;  ///< -1 below the obstacle, 1 above, 0 unknown
  std::int32_t closing_force_ = 50;
  std::int32_t opening_force_ = 50;
  std::uint8_t can_id_ = 1;
  std::uint8_t stored_can_id_ = 1;
  std::int32_t baud_index_ = 0;  ///< as stored; the sim line does not depend on it
  TimePoint last_update_{};
  std::vector<Outgoing> unsolicited_;
  std::uint64_t requests_seen_ = 0;
  protocol::GripStatus noted_grip_ = protocol::GripStatus::moving;
  TimePoint grip_since_{};
};

}  // namespace dh3::sim
