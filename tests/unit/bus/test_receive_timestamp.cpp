// receive_timestamp: the kernel's stamp from a recvmsg() control buffer, as
// the socketcan bus and dh3-sim's interval check take it from CAN and TCP
// sockets.

#include "dh3/bus/receive_timestamp.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <ctime>

namespace dh3::bus {
namespace {

using namespace std::chrono_literals;

TEST(ReceiveTimestamp, ReadsNanosecondAndMicrosecondStamps) {
  alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(timespec))] = {};
  msghdr message{};
  message.msg_control = control;
  message.msg_controllen = sizeof control;
  cmsghdr* c = CMSG_FIRSTHDR(&message);
  c->cmsg_level = SOL_SOCKET;
  c->cmsg_type = SCM_TIMESTAMPNS;
  c->cmsg_len = CMSG_LEN(sizeof(timespec));
  const timespec ns{1700000000, 123456789};
  std::memcpy(CMSG_DATA(c), &ns, sizeof ns);
  EXPECT_EQ(receive_timestamp(message), std::chrono::seconds(1700000000) + 123456789ns);

  c->cmsg_type = SCM_TIMESTAMP;
  c->cmsg_len = CMSG_LEN(sizeof(timeval));
  const timeval us{1700000000, 654321};
  std::memcpy(CMSG_DATA(c), &us, sizeof us);
  EXPECT_EQ(receive_timestamp(message), std::chrono::seconds(1700000000) + 654321us);

  c->cmsg_type = SCM_RIGHTS;
  EXPECT_EQ(receive_timestamp(message), std::nullopt);
  message.msg_controllen = 0;
  EXPECT_EQ(receive_timestamp(message), std::nullopt);
}

Duration wall_clock_now() {
  timespec now{};
  ::clock_gettime(CLOCK_REALTIME, &now);
  return std::chrono::seconds(now.tv_sec) + std::chrono::nanoseconds(now.tv_nsec);
}

TEST(ReceiveTimestamp, AnUnstampedReadArrivedWhenItWasReadByTheStampsClock) {
  int pair[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_DGRAM, 0, pair), 0);  // never asked to stamp
  const unsigned char sent = 7;
  ASSERT_EQ(::send(pair[1], &sent, 1, 0), 1);
  unsigned char buffer[4];
  const Duration before = wall_clock_now();
  const StampedRead read = read_stamped(pair[0], buffer, 0);
  const Duration arrival = arrival_time(read.stamp);
  const Duration after = wall_clock_now();
  ::close(pair[0]);
  ::close(pair[1]);
  ASSERT_EQ(read.got, 1);
  EXPECT_EQ(read.stamp, std::nullopt);
  EXPECT_GE(arrival, before);
  EXPECT_LE(arrival, after);
}

TEST(ReceiveTimestamp, AStampedReadArrivedAtItsStamp) {
  StampedRead read;
  read.got = 1;
  read.stamp = std::chrono::seconds(1700000000) + 5ns;
  EXPECT_EQ(arrival_time(read.stamp), std::chrono::seconds(1700000000) + 5ns);
}

}  // namespace
}  // namespace dh3::bus
