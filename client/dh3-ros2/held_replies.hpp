#pragma once
// Replies that wait for the client's reply reader. An rmw_fastrtps client may
// write a request before this side's reply writer has matched its reply
// reader (the client sees its own endpoints matched first); a reply written
// then is lost, because the reply topic is VOLATILE. So a reply to a reader
// not matched yet is held until the writer matches that reader, and written
// then, on the thread that reports the match. Nothing blocks meanwhile: the
// request listener goes on taking requests.
//
// A reader that never matches (a client that died, or a participant that
// writes requests and reads no replies) must not hold memory for ever: a reply
// is held at most `hold_limit`, and at most `cap` replies are held in all, the
// oldest dropped beyond it.
//
// Thread-safe: replies come from the request listener and the goal workers,
// matches from Fast DDS's listener threads. Knows no Fast DDS entity: the
// caller writes what it returns. Told the time by its caller.

#include <chrono>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace dh3::ros2 {

class HeldReplies {
 public:
  using Clock = std::chrono::steady_clock;
  /// Writes one reply; called outside the lock.
  using Write = std::function<void()>;

  HeldReplies(Clock::duration hold_limit, std::size_t cap);

  /// Whether `write` must run now: true if `reader` is matched; else it is
  /// held (and false returned). `reader` names the client's reply reader.
  [[nodiscard]] bool admit(const std::string& reader, Write write, Clock::time_point now);
  /// The writer matched (`matched`) or lost `reader`. Returns the replies held
  /// for it, to write now, oldest first.
  [[nodiscard]] std::vector<Write> reader_matched(const std::string& reader, bool matched,
                                                  Clock::time_point now);

  [[nodiscard]] std::size_t held() const;
  /// How many replies were dropped (expired or pushed out by the cap).
  [[nodiscard]] std::size_t dropped() const;

 private:
  struct Held {
    std::string reader;
    Clock::time_point until;
    Write write;
  };
  void expire_locked(Clock::time_point now);

  const Clock::duration hold_limit_;
  const std::size_t cap_;
  mutable std::mutex mutex_;
  std::set<std::string> matched_;
  std::deque<Held> held_;  // oldest first
  std::size_t dropped_ = 0;
};

}  // namespace dh3::ros2
