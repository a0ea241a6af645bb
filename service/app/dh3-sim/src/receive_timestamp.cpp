#include "dh3/sim_server/receive_timestamp.hpp"

#include <sys/time.h>

#include <algorithm>
#include <cerrno>
#include <ctime>

namespace dh3::sim {

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

}  // namespace dh3::sim
