#pragma once
// The client library's own types: what a program sees of hands, services,
// events and command results. Plain C++ (no Fast DDS, no generated code), so
// users of the library do not inherit the middleware's headers. The wire types
// (idl/dh3.idl, dh3::msg) map onto these one to one.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "dh3/base/event_kind.hpp"
#include "dh3/export.hpp"

namespace dh3 {

/// The outcome of a call. The first group comes from the service (the wire's
/// ResultCode); the second is the client's own when no service answer exists.
enum class Code : std::uint8_t {
  ok,
  invalid_argument,  ///< out-of-range value or malformed request; never sent to a bus
  unknown_hand,      ///< no such service, bus or hand (or a name that matches none)
  timeout,           ///< the service says: the hand did not answer in time
  bus_down,          ///< the link to the bus is down
  busy,              ///< the hand's command queue is full
  not_initialized,   ///< motion before initialization
  denied,            ///< administrative command not allowed, or another client holds the lease;
                     ///< also the client's own for a read-only identity (never sent)
  cancelled,         ///< superseded by a newer motion command, a stop, or shutdown
  failed,            ///< the hand answered, but the command did not succeed

  /// The hand's service was not found on the domain, or not ready for this
  /// client, before the deadline; the message says what discovery showed.
  no_service,
  no_reply,       ///< the request went out but no reply came before the deadline
  service_lost,   ///< the service left the domain (or restarted) while the call was pending
  not_connected,  ///< the client has no DDS participant (set-up failed, or the client is gone)
};

/// "OK", "INVALID_ARGUMENT", ... "SERVICE_LOST": the wire's spelling for the
/// service's codes, the same style for the client's own.
DH3_CLIENT_API std::string_view to_string(Code code);

enum class GraspOutcome : std::uint8_t { none, grasped, missed };
DH3_CLIENT_API std::string_view to_string(GraspOutcome outcome);

/// The grip outcomes have the names of the GRASP reply and the events
/// (GRASPED, MISSED, DROPPED) wherever they appear.
enum class GripState : std::uint8_t { unknown, moving, arrived, grasped, missed, dropped };
DH3_CLIENT_API std::string_view to_string(GripState state);

enum class RotationState : std::uint8_t { unknown, moving, arrived, blocked };
DH3_CLIENT_API std::string_view to_string(RotationState state);

// EventKind (online, offline, ... fault, and the client's own taken_over) is
// dh3/base/event_kind.hpp's, the one list the service's layers use too.
DH3_CLIENT_API std::string_view to_string(EventKind kind);

/// A hand, unique in a DDS domain.
struct HandAddress {
  std::string service;
  std::string bus;
  std::uint16_t can_id = 0;

  /// "service/bus/id"
  [[nodiscard]] DH3_CLIENT_API std::string to_string() const;
  friend bool operator==(const HandAddress& a, const HandAddress& b) {
    return a.can_id == b.can_id && a.service == b.service && a.bus == b.bus;
  }
  friend bool operator!=(const HandAddress& a, const HandAddress& b) { return !(a == b); }
  friend bool operator<(const HandAddress& a, const HandAddress& b) {
    if (a.service != b.service) return a.service < b.service;
    if (a.bus != b.bus) return a.bus < b.bus;
    return a.can_id < b.can_id;
  }
};

/// What a call returns: always a code and, unless OK, a message that says why.
/// The other fields matter for some commands only.
struct Reply {
  Code code = Code::ok;
  std::string message;
  /// READ: the value read. GRASP: the final position. Writes: the value written.
  std::int32_t value = 0;
  /// GRASP: grasped (holding something) or missed (closed on nothing).
  GraspOutcome grasp = GraspOutcome::none;
  /// SCAN: the CAN IDs that answered.
  std::vector<std::uint16_t> found_ids;
  /// Lease commands, and commands refused because of a lease: who holds it.
  std::string lease_holder;

  [[nodiscard]] bool ok() const { return code == Code::ok; }
  explicit operator bool() const { return ok(); }
};

/// A value, or why there is none (lookups: find_hand, wait_for_hand).
template <typename T>
class Found {
 public:
  Found(T value) : value_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  Found(Code code, std::string message) : code_(code), message_(std::move(message)) {}

  [[nodiscard]] bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }
  [[nodiscard]] Code code() const { return code_; }
  [[nodiscard]] const std::string& message() const { return message_; }
  T& value() { return *value_; }
  const T& value() const { return *value_; }
  T& operator*() { return *value_; }
  const T& operator*() const { return *value_; }
  T* operator->() { return &*value_; }
  const T* operator->() const { return &*value_; }

 private:
  std::optional<T> value_;
  Code code_ = Code::ok;
  std::string message_;
};

/// The latest status the service published for a hand.
struct HandStatus {
  HandAddress address;
  std::string name;  ///< from the service's config, may be empty
  bool online = false;
  bool initialized = false;
  GripState grip = GripState::unknown;
  /// -1 until read. Not read while the fingers move or hold (their status is
  /// read in every frame instead): during a motion it is where they were
  /// before it; a sample with where they stopped follows the motion's event
  /// within about one command interval.
  std::int32_t position = -1;
  std::int32_t target_position = -1;  ///< -1 until written
  std::int32_t closing_force = 0;
  std::int32_t opening_force = 0;
  std::int32_t rotation = -1;
  std::int32_t rotation_target = -1;
  RotationState rotation_state = RotationState::unknown;
  std::int32_t firmware_version = 0;  ///< raw 0x1301 value
  std::string firmware_version_text;  ///< "4.1.2.0"
  Code last_error = Code::ok;
  std::string last_error_message;
  std::string lease_holder;        ///< empty when nobody holds a lease
  std::uint64_t timestamp_ns = 0;  ///< the service's wall clock, ns since the epoch
  std::uint64_t update_seq = 0;    ///< increments on every change of this hand
  /// When the values were read from the hand: the hand's last reply that went
  /// into this sample, on the service's wall clock (ns since the epoch); 0 before
  /// the hand ever answered. While nothing changes, a sample with the same values
  /// and a newer read_at_ns follows about every poll_interval_idle of the bus.
  std::uint64_t read_at_ns = 0;
  /// True when the client marked the hand offline itself because its service
  /// left the domain without saying so (killed, network lost).
  bool service_lost = false;
};

struct HandEvent {
  HandAddress hand;
  std::string name;
  EventKind kind = EventKind::fault;
  /// arrived, grasped, missed: where the fingers stopped; rotation_arrived,
  /// rotation_blocked: where the rotation stopped. Empty when it was not read
  /// yet as the event went out: an event goes out on the status read that
  /// shows the end, about one command interval after it at most, and the
  /// position is read in the next frame; the status that follows (and the
  /// reply to a grasp or release) says it. dropped: where the fingers held
  /// the object. Other events: the position as last read (empty before any).
  std::optional<std::int32_t> position;
  std::int32_t target = 0;  ///< target in force; after a stop, the target of the motion it ended
  /// grasped: the closing force it holds with; arrived, missed and the rotation
  /// events: the status value read; dropped, fault: the status value; online:
  /// the raw firmware version; offline: unanswered requests in a row.
  std::int32_t value = 0;
  std::string message;
  /// Wall time (ns since the Unix epoch) the service saw the change; for an
  /// event the client made itself, when it made it.
  std::uint64_t timestamp_ns = 0;
  std::uint64_t event_seq = 0;  ///< per service; 0 for events the client made itself
  /// True for the events the client makes itself: OFFLINE when a service
  /// disappears, ONLINE when it is back (event_seq 0).
  bool from_client = false;
};

/// What a HandEvent's value means, named: `name` is the field it is shown
/// as in `dh3ctl --json events` and dh3-web's event stream.
struct EventValue {
  std::string_view name;
  std::int32_t value = 0;
};
/// grasped: {"closing_force", N}; arrived, missed, dropped: {"grip_status",
/// the status register's value}; the rotation events: {"rotation_status",
/// ...}; online: {"firmware_version", raw}; offline: {"unanswered_requests",
/// N} (0: the link went down, or the service stopped). nullopt where the
/// value says nothing the kind and the message do not (initialized,
/// init_failed, fault, taken_over). Any thread.
[[nodiscard]] DH3_CLIENT_API std::optional<EventValue> named_value(const HandEvent& event);

struct HandInfo {
  std::uint16_t can_id = 0;
  std::string name;
};

struct BusInfo {
  std::string name;
  std::string spec;  ///< e.g. "tcp:127.0.0.1:9000", "sim:1,2,3"
  bool link_up = false;
  std::vector<HandInfo> hands;
};

struct ServiceInfo {
  std::string name;
  std::string version;
  std::string host;
  bool admin_allowed = false;
  std::vector<BusInfo> buses;
  std::uint64_t started_ns = 0;
  /// The service is on the domain now and its request and reply topics are
  /// matched with this client: calls to it go out at once.
  bool ready = false;
};

}  // namespace dh3
