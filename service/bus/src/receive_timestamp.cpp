#include "dh3/bus/receive_timestamp.hpp"

#include <sys/time.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <ctime>

namespace dh3::bus {

std::optional<int> enable_receive_timestamps(int fd) {
  const int on = 1;
  if (::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0) return errno;
  return std::nullopt;
}

std::optional<Duration> receive_timestamp(const msghdr& message) {
  // CMSG_NXTHDR takes a non-const msghdr; it only reads it.
  auto& readable = const_cast<msghdr&>(message);
  for (cmsghdr* c = CMSG_FIRSTHDR(&readable); c != nullptr; c = CMSG_NXTHDR(&readable, c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SCM_TIMESTAMPNS && c->cmsg_len >= CMSG_LEN(sizeof(timespec))) {
      timespec stamp{};
      std::copy_n(CMSG_DATA(c), sizeof stamp, reinterpret_cast<unsigned char*>(&stamp));
      return std::chrono::seconds(stamp.tv_sec) + std::chrono::nanoseconds(stamp.tv_nsec);
    }
    if (c->cmsg_type == SCM_TIMESTAMP && c->cmsg_len >= CMSG_LEN(sizeof(timeval))) {
      timeval stamp{};
      std::copy_n(CMSG_DATA(c), sizeof stamp, reinterpret_cast<unsigned char*>(&stamp));
      return std::chrono::seconds(stamp.tv_sec) + std::chrono::microseconds(stamp.tv_usec);
    }
  }
  return std::nullopt;
}

StampedRead read_stamped(int fd, std::span<unsigned char> buffer, int flags) {
  // Room for both stamp kinds, whichever the kernel sends.
  alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(timespec)) * 2];
  iovec io{buffer.data(), buffer.size()};
  msghdr message{};
  message.msg_iov = &io;
  message.msg_iovlen = 1;
  message.msg_control = control;
  message.msg_controllen = sizeof control;
  StampedRead read;
  read.got = ::recvmsg(fd, &message, flags);
  if (read.got < 0) {
    read.error = errno;
    return read;
  }
  read.truncated = (message.msg_flags & MSG_TRUNC) != 0;
  read.stamp = receive_timestamp(message);
  return read;
}

Duration arrival_time(const std::optional<Duration>& stamp) {
  if (stamp) return *stamp;
  return std::chrono::duration_cast<Duration>(
      std::chrono::system_clock::now().time_since_epoch());  // CLOCK_REALTIME
}

}  // namespace dh3::bus
