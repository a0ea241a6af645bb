// ReceiveQueues (client/src/receive_queues.hpp) on real sockets of this
// process: a datagram waiting unread in a UDP socket is lag, none is current.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include "receive_queues.hpp"

namespace dh3::detail {
namespace {

/// A UDP socket bound to a free loopback port.
class LoopbackSocket {
 public:
  LoopbackSocket() : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    address_.sin_family = AF_INET;
    address_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address_.sin_port = 0;
    bound_ = fd_ >= 0 &&
             ::bind(fd_, reinterpret_cast<const sockaddr*>(&address_), sizeof(address_)) == 0;
    socklen_t length = sizeof(address_);
    bound_ = bound_ &&
             ::getsockname(fd_, reinterpret_cast<sockaddr*>(&address_), &length) == 0;
  }
  ~LoopbackSocket() {
    if (fd_ >= 0) ::close(fd_);
  }
  LoopbackSocket(const LoopbackSocket&) = delete;
  LoopbackSocket& operator=(const LoopbackSocket&) = delete;

  [[nodiscard]] bool bound() const { return bound_; }
  /// Sends a datagram to itself.
  bool send_to_self() const {
    const char byte = 'x';
    return ::sendto(fd_, &byte, 1, 0, reinterpret_cast<const sockaddr*>(&address_),
                    sizeof(address_)) == 1;
  }
  bool receive() const {
    char byte = 0;
    return ::recv(fd_, &byte, 1, 0) == 1;
  }

 private:
  int fd_;
  sockaddr_in address_{};
  bool bound_ = false;
};

TEST(ReceiveQueues, ADatagramWaitingUnreadIsLagAndNoneIsCurrent) {
  LoopbackSocket socket;
  ASSERT_TRUE(socket.bound());
  EXPECT_EQ(ReceiveQueues::look_once(), ReceiveState::current);
  ASSERT_TRUE(socket.send_to_self());
  EXPECT_EQ(ReceiveQueues::look_once(), ReceiveState::behind);
  EXPECT_EQ(ReceiveQueues::look(), ReceiveState::behind) << "still waiting on every try";
  ASSERT_TRUE(socket.receive());
  EXPECT_EQ(ReceiveQueues::look_once(), ReceiveState::current);
}

TEST(ReceiveQueues, OnlyAParticipantThatReceivesOverUdpAloneLooks) {
  LoopbackSocket socket;
  ASSERT_TRUE(socket.bound());
  ASSERT_TRUE(socket.send_to_self());
  EXPECT_EQ(ReceiveQueues::looker(false)(), ReceiveState::unknown);
  EXPECT_EQ(ReceiveQueues::looker(true)(), ReceiveState::behind);
  ASSERT_TRUE(socket.receive());
}

}  // namespace
}  // namespace dh3::detail
