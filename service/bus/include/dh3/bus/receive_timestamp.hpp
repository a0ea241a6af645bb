#pragma once
// The kernel's receive time of what a recvmsg() read: for the socketcan bus's
// flight recorder, and for dh3-sim's interval check, where the time of reading
// includes however long the server's loop was not scheduled, which made frames
// the service spaced correctly look too close. CAN sockets stamp each frame;
// TCP stamps the newest segment of a read, which for frames one interval apart
// is the frame itself.
//
// Threading: pure functions.

#include <sys/socket.h>

#include <sys/types.h>

#include <optional>
#include <span>

#include "dh3/base/clock.hpp"

namespace dh3::bus {

/// Asks the kernel to stamp what `fd` receives (SO_TIMESTAMPNS); the OS's
/// errno if it refuses.
[[nodiscard]] std::optional<int> enable_receive_timestamps(int fd);

/// The kernel's receive time carried in a recvmsg() control buffer
/// (SCM_TIMESTAMPNS or SCM_TIMESTAMP), as time since the epoch of
/// CLOCK_REALTIME; nullopt if the message carries none.
[[nodiscard]] std::optional<Duration> receive_timestamp(const msghdr& message);

/// What one recvmsg() read: the byte count, or -1 with the OS's errno.
struct StampedRead {
  ssize_t got = 0;
  int error = 0;
  bool truncated = false;  ///< a datagram longer than the buffer
  std::optional<Duration> stamp;
};

/// One recvmsg() on `fd` into `buffer`, with room for the kernel's stamp.
[[nodiscard]] StampedRead read_stamped(int fd, std::span<unsigned char> buffer, int flags);

/// When a read reached the socket, as time since the epoch of CLOCK_REALTIME:
/// its `stamp`, or the time of this call if the kernel left it unstamped. Linux switches stamping on by deferred work when the first
/// socket asks for it, so the frames of the next moments may carry none;
/// timed by another clock than the stamps beside them, two frames a round
/// trip apart would look years apart.
[[nodiscard]] Duration arrival_time(const std::optional<Duration>& stamp);

}  // namespace dh3::bus
