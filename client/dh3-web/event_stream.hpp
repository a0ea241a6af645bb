#pragma once
// The push stream behind GET /api/stream: every status sample and event the
// client receives, as Server-Sent Events, to every open stream.
//
// Each stream has its own queue, so a slow browser delays nobody else: a
// status waiting in a queue is replaced by the same hand's newer one (a page
// needs the latest, not every poll), events are kept in order. A stream whose
// queue still overflows is ended; the browser reconnects and starts from a
// fresh snapshot. A new stream begins with the services, every hand's status,
// the last events (the page's log) and the alarm list, then goes live; the
// list is sent again whole when it changes. The services are sent
// again every couple of seconds (heartbeat()): the page sees a lost service
// and a stalled stream within seconds.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "dh3/client.hpp"

namespace dh3::web {

struct EventStreamOptions {
  /// Events a new stream starts with.
  std::size_t backlog = 100;
  /// Messages a stream may have waiting before it is ended.
  std::size_t queue_limit = 2000;
  /// Streams open at once; open() refuses the one past them.
  std::size_t max_readers = 64;
};

class EventStream {
 public:
  class Reader;

  EventStream(Client& client, EventStreamOptions options = {});
  ~EventStream();
  EventStream(const EventStream&) = delete;
  EventStream& operator=(const EventStream&) = delete;

  /// A new stream, primed with the snapshot; nullptr when max_readers are open
  /// (a stream is open while its Reader lives).
  std::shared_ptr<Reader> open();
  [[nodiscard]] std::size_t max_readers() const { return options_.max_readers; }
  /// Every service's info as SSE messages (a keep-alive comment when there is
  /// none): what each stream sends every couple of seconds.
  [[nodiscard]] std::string heartbeat() const;
  /// The cell's alarm list (CellAlarms::alarms_json()) to every stream, and
  /// to each new one first; an older `version` than the one sent is dropped.
  void publish_alarms(std::uint64_t version, std::string json);
  /// Ends every stream (shutdown): their next() returns nullopt.
  void close();

  class Reader {
   public:
    /// What is waiting, as SSE text, after at most `wait`; "" when nothing
    /// came (send a keep-alive), nullopt when the stream has ended.
    std::optional<std::string> next(std::chrono::milliseconds wait);

   private:
    friend class EventStream;
    struct Message {
      std::string hand;  ///< a status's hand, empty for other messages
      std::string text;  ///< "event: status\ndata: {...}\n\n"
    };
    void push(std::string hand, std::string text, std::size_t limit);

    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<Message> queue_;
    bool ended_ = false;
  };

 private:
  [[nodiscard]] std::string service_messages() const;
  void on_status(const HandStatus& status);
  void on_event(const HandEvent& event);
  void broadcast(const std::string& hand, const std::string& text);

  Client& client_;
  EventStreamOptions options_;
  std::mutex mutex_;
  std::vector<std::weak_ptr<Reader>> readers_;
  std::deque<std::string> backlog_;
  std::uint64_t alarms_version_ = 0;
  std::string alarms_;  ///< the newest alarm list as an SSE message, "" before any
  bool closed_ = false;
  Subscription status_subscription_;
  Subscription event_subscription_;
};

/// "event: NAME\ndata: JSON\n\n"
[[nodiscard]] std::string sse_message(std::string_view name, std::string_view json);

}  // namespace dh3::web
