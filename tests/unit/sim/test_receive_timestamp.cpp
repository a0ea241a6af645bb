// receive_timestamp: the kernel's stamp from a recvmsg() control buffer, as
// dh3-sim's interval check takes it from CAN and TCP sockets.

#include "dh3/sim_server/receive_timestamp.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <chrono>
#include <cstring>

namespace dh3::sim {
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

}  // namespace
}  // namespace dh3::sim
