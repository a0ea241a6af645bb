#pragma once
// Small POSIX helpers: an owning file descriptor, a cross-thread wake-up
// (eventfd), a bounded poll and errno text.

#include <poll.h>

#include <cstdint>
#include <span>
#include <string>

#include "dh3/base/clock.hpp"

namespace dh3 {

/// Owns a file descriptor and closes it once. Move-only.
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  ~UniqueFd() { reset(); }
  UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept {
    if (this != &other) reset(other.release());
    return *this;
  }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;

  [[nodiscard]] int get() const { return fd_; }
  [[nodiscard]] bool valid() const { return fd_ >= 0; }
  explicit operator bool() const { return valid(); }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }
  void reset(int fd = -1);

 private:
  int fd_ = -1;
};

/// A wake-up another thread can trigger to end a poll early (eventfd). The
/// owner puts fd() in its poll set and calls drain() when it fires.
class WakeFd {
 public:
  WakeFd();
  /// False if the eventfd could not be created (fd limit reached); then
  /// wake() does nothing and a poll simply runs to its timeout.
  [[nodiscard]] bool valid() const { return fd_.valid(); }
  [[nodiscard]] int fd() const { return fd_.get(); }
  /// Any thread. Async-signal-safe.
  void wake() const;
  /// Consumes pending wake-ups.
  void drain() const;

 private:
  UniqueFd fd_;
};

/// strerror for `error`, thread-safe.
[[nodiscard]] std::string errno_text(int error);

/// A poll timeout never shorter than `timeout` rounded up to whole
/// microseconds (a positive sub-millisecond timeout must not become a busy
/// loop) and never negative.
[[nodiscard]] timespec to_timespec(Duration timeout);

/// ppoll() that retries on EINTR with the same timeout (a signal can only
/// shorten the wait, and a caller loops anyway). Returns ppoll's result; on
/// failure errno is set.
int poll_fds(std::span<pollfd> fds, Duration timeout);

/// Sets O_NONBLOCK. Returns false (errno set) on failure.
bool set_nonblocking(int fd);

}  // namespace dh3
