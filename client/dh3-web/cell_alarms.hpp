#pragma once
// The alarm list of this console, fed by what its client sees and by the
// commands that fail through it: a hand offline, a service lost and a bus down
// (conditions, watched every `watch_every` and on every status; a service is
// lost once it was ready, and whether a hand answers is not known while its
// service is not ready: a console started beside its cell raises nothing for
// the moments the cell takes to come up), an object
// dropped, an initialization failed and a fault (the services' events), a
// command failed (record_failure()). The rules of the list are AlarmList's;
// this owns it under a lock, tells it the wall time and says when it changed.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>

#include "alarm_list.hpp"
#include "dh3/client.hpp"

namespace dh3::web {

class CellAlarms {
 public:
  /// Called with the list's version and JSON (alarms_json()) after each
  /// change, without the lock held; two calls may come in either order (the
  /// version says which is newer).
  using Listener = std::function<void(std::uint64_t version, const std::string& json)>;

  explicit CellAlarms(Client& client, std::size_t limit = 200,
                      std::chrono::milliseconds watch_every = std::chrono::milliseconds(500));
  ~CellAlarms();
  CellAlarms(const CellAlarms&) = delete;
  CellAlarms& operator=(const CellAlarms&) = delete;

  /// Set once, before anything can change (the stream that sends the changes).
  void set_listener(Listener listener);

  /// A command sent through dh3-web failed: `http_status` and `code` as its
  /// reply says them.
  void record_failure(const std::string& hand, const std::string& command, int http_status,
                      const std::string& code, const std::string& message);
  /// The alarm acknowledged, as JSON; nullopt when there is no such alarm.
  std::optional<std::string> acknowledge(std::uint64_t id);
  /// {"type": "alarms", "version": N, "alarms": [newest first]}
  [[nodiscard]] std::string alarms_json() const;

 private:
  void watch();
  void watch_services();
  void watch_status(const HandStatus& status);
  void on_event(const HandEvent& event);
  /// Applies `change` to the list under the lock; tells the listener if it changed.
  void update(const std::function<bool(AlarmList&, std::uint64_t now_ns)>& change);
  [[nodiscard]] std::string json_locked() const;

  Client& client_;
  std::chrono::milliseconds watch_every_;
  mutable std::mutex mutex_;
  AlarmList list_;
  std::uint64_t failures_ = 0;
  /// Whether each service seen is ready, as the last watch found it.
  std::map<std::string, bool> ready_;
  /// Services that were ready once: a service that was never ready was not lost.
  std::set<std::string> ever_ready_;
  Listener listener_;
  bool stopping_ = false;
  std::condition_variable stop_;
  Subscription status_subscription_;
  Subscription event_subscription_;
  std::thread watcher_;
};

}  // namespace dh3::web
