#include "dh3/base/fd_util.hpp"

#include <fcntl.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

namespace dh3 {

void UniqueFd::reset(int fd) {
  if (fd_ >= 0) ::close(fd_);  // close() errors on Linux still free the fd
  fd_ = fd;
}

WakeFd::WakeFd() : fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {}

void WakeFd::wake() const {
  if (!fd_.valid()) return;
  const std::uint64_t one = 1;
  // EAGAIN means the counter is saturated: a wake-up is already pending.
  [[maybe_unused]] const auto written = ::write(fd_.get(), &one, sizeof one);
}

void WakeFd::drain() const {
  if (!fd_.valid()) return;
  std::uint64_t count = 0;
  [[maybe_unused]] const auto got = ::read(fd_.get(), &count, sizeof count);
}

std::string errno_text(int error) {
  char buffer[256] = {};
  // GNU strerror_r returns the message, which may or may not be `buffer`.
  return ::strerror_r(error, buffer, sizeof buffer);
}

timespec to_timespec(Duration timeout) {
  using std::chrono::ceil;
  using std::chrono::microseconds;
  using std::chrono::nanoseconds;
  using std::chrono::seconds;
  if (timeout <= Duration::zero()) return timespec{0, 0};
  // Cap at a day: larger values gain nothing and could overflow time_t maths.
  const auto capped = std::min<Duration>(timeout, std::chrono::hours(24));
  const auto total = std::chrono::duration_cast<nanoseconds>(ceil<microseconds>(capped));
  const auto whole = std::chrono::duration_cast<seconds>(total);
  return timespec{static_cast<time_t>(whole.count()), static_cast<long>((total - whole).count())};
}

int poll_fds(std::span<pollfd> fds, Duration timeout) {
  const timespec wait = to_timespec(timeout);
  for (;;) {
    const int ready = ::ppoll(fds.data(), fds.size(), &wait, nullptr);
    if (ready >= 0 || errno != EINTR) return ready;
  }
}

bool set_nonblocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0) return false;
  return ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) == 0;
}

}  // namespace dh3
