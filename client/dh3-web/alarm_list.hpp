#pragma once
// The cell's alarms as dh3-web keeps them: one list for every page and API
// client of this console, so an alarm acknowledged on one screen is
// acknowledged on all and a reload forgets nothing.
// Pure: it is told the time of each change; it reads no clock and is not
// thread-safe (CellAlarms owns it under a lock).
//
// A condition (a hand offline, a bus down, a service lost) is listed while it
// lasts and after, marked over, until acknowledged; acknowledged while it
// lasts, it is not raised again until it ends and comes back. An occurrence
// (an object dropped, a command failed) is listed once until acknowledged.
// Acknowledged alarms stay in the list as its history; when the list is full
// the oldest acknowledged go first, then the oldest over, then the oldest.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace dh3::web {

struct Alarm {
  std::uint64_t id = 0;   ///< unique in this dh3-web's life, never reused
  std::string key;        ///< "offline:svc/bus0/4", "command:3", ...
  std::string text;       ///< in the page's words
  bool condition = false; ///< a condition (it can end) or an occurrence
  bool active = true;     ///< the condition lasts (an occurrence is always active)
  bool acknowledged = false;
  std::uint64_t since_ns = 0;  ///< wall time, ns since the epoch
  std::uint64_t over_ns = 0;   ///< when the condition ended; 0 while it lasts
  std::uint64_t acknowledged_ns = 0;
};

class AlarmList {
 public:
  explicit AlarmList(std::size_t limit = 200);

  /// Whether the condition `key` holds at `now_ns`: raised (or its text
  /// updated) while it does, marked over when it stops. True if the list changed.
  bool holds(const std::string& key, bool condition, const std::string& text,
             std::uint64_t now_ns);
  /// An occurrence; ignored (false) if `key` was raised before.
  bool raise_once(const std::string& key, const std::string& text, std::uint64_t now_ns);
  /// The alarm acknowledged; nullopt if no alarm has this id (any more).
  /// Acknowledging twice is harmless: two operators at once.
  std::optional<Alarm> acknowledge(std::uint64_t id, std::uint64_t now_ns);

  /// Newest first.
  [[nodiscard]] std::vector<Alarm> alarms() const;
  /// Increments on every change: a stream sends the list when it moved.
  [[nodiscard]] std::uint64_t version() const { return version_; }

 private:
  Alarm* find_unacknowledged(const std::string& key);
  void add(Alarm alarm);
  void changed() { ++version_; }

  std::size_t limit_;
  std::deque<Alarm> alarms_;  ///< oldest first
  std::set<std::string> suppressed_;  ///< conditions acknowledged while they last
  std::set<std::string> occurred_;    ///< occurrences raised lately
  std::deque<std::string> occurred_order_;  ///< bounds occurred_, oldest first
  std::uint64_t next_id_ = 1;
  std::uint64_t version_ = 0;
};

}  // namespace dh3::web
