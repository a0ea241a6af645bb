// The CAN transport behind `dh3-sim --can`, in-process on the fd path it shares
// with real CAN sockets: the tests hand it one end of an AF_UNIX SOCK_SEQPACKET
// socketpair carrying struct can_frame and play the bus on the other end. The
// payloads are the protocol document's examples, byte for byte (the CAN form is
// the 14-byte form without header, gripper ID and end; the ID is the CAN ID).

#include <gtest/gtest.h>
#include <linux/can.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "dh3/sim_server/can_server.hpp"
#include "support/raw_tcp_client.hpp"
#include "unit/sim/server_test_support.hpp"

namespace dh3::sim {
namespace {

using namespace std::chrono_literals;
using dh3::test::bytes_from_hex;
constexpr auto hand = test::fast_hand;

constexpr int kDeadlineMs = 10000;

/// Both ends of a socketpair: `bus` is the test's, `server` goes to the server.
struct BusPair {
  BusPair() {
    int fds[2] = {-1, -1};
    EXPECT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds), 0);
    bus = fds[0];
    server = fds[1];
  }
  ~BusPair() {
    if (bus >= 0) ::close(bus);
  }
  BusPair(const BusPair&) = delete;
  BusPair& operator=(const BusPair&) = delete;
  int bus = -1;
  int server = -1;  ///< owned by the server once opened
};

can_frame frame_of(canid_t id, std::string_view hex) {
  can_frame frame{};
  frame.can_id = id;
  const std::vector<std::uint8_t> bytes = bytes_from_hex(hex);
  frame.len = static_cast<std::uint8_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), frame.data);
  return frame;
}

void send_frame(int fd, const can_frame& frame) {
  ASSERT_EQ(::send(fd, &frame, sizeof frame, MSG_NOSIGNAL), static_cast<ssize_t>(sizeof frame));
}

/// The next frame on `fd` as "ID: payload hex", or "<nothing>" within the deadline.
std::string next_frame(int fd, int timeout_ms = kDeadlineMs) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, timeout_ms) <= 0) return "<nothing>";
  can_frame frame{};
  const ssize_t got = ::recv(fd, &frame, sizeof frame, MSG_DONTWAIT);
  if (got != static_cast<ssize_t>(sizeof frame)) return "<" + std::to_string(got) + " bytes>";
  return std::to_string(frame.can_id) + ": " +
         dh3::protocol::to_hex(std::span(frame.data, frame.len));
}

/// Sends `request` to hand `id` and returns the next frame on the bus.
std::string exchange(int fd, canid_t id, std::string_view request) {
  send_frame(fd, frame_of(id, request));
  return next_frame(fd);
}

/// A server on its own thread; its control channel is a pair of pipes.
class Running : public test::ServerThread<CanServer> {
 public:
  Running(CanServerOptions options, bus::CanSocketOpener opener,
          const Clock& clock = SystemClock::instance())
      : Running(std::make_unique<Channel>(), std::move(options), std::move(opener), clock) {}
  // The server stops before its control channel closes.
  ~Running() { stop(); }
  Running(const Running&) = delete;
  Running& operator=(const Running&) = delete;

  /// Sends a control command and returns its answer.
  std::string control(const std::string& command) {
    test::write_text(channel_->in.write_end(), command + "\n");
    return test::read_line(channel_->out.read_end());
  }

 private:
  struct Channel {
    test::Pipe in;
    test::Pipe out;
  };
  Running(std::unique_ptr<Channel> channel, CanServerOptions options,
          bus::CanSocketOpener opener, const Clock& clock)
      : ServerThread(open_or_null(*channel, std::move(options), std::move(opener), clock)),
        channel_(std::move(channel)) {}
  static std::unique_ptr<CanServer> open_or_null(const Channel& channel, CanServerOptions options,
                                                 bus::CanSocketOpener opener, const Clock& clock) {
    options.control_in = channel.in.read_end();
    options.control_out = channel.out.write_end();
    auto opened = CanServer::open(std::move(options), std::move(opener), clock);
    EXPECT_TRUE(opened.ok()) << (opened.ok() ? "" : opened.error());
    return opened ? std::move(opened.value()) : nullptr;
  }
  std::unique_ptr<Channel> channel_;
};

/// An opener that hands over `fd` once.
bus::CanSocketOpener once(int fd) {
  return [fd]() -> Result<UniqueFd, std::string> { return UniqueFd(fd); };
}

CanServerOptions options_with(std::vector<SimHandOptions> hands) {
  CanServerOptions options;
  options.interface_name = "testcan";
  options.hands = std::move(hands);
  return options;
}

TEST(CanServer, AnswersTheDocumentsExamplesByteForByte) {
  BusPair pair;
  Running running(options_with({hand(1)}), once(pair.server));
  ASSERT_TRUE(running.started());
  // Read whether feedback is enabled: "no"; set it; read again: "yes".
  EXPECT_EQ(exchange(pair.bus, 1, "08 01 00 00 00 00 00 00"), "1: 08 01 00 00 00 00 00 00");
  EXPECT_EQ(exchange(pair.bus, 1, "08 01 01 00 00 00 00 00"), "1: 08 01 01 00 A5 00 00 00");
  EXPECT_EQ(exchange(pair.bus, 1, "08 01 00 00 00 00 00 00"), "1: 08 01 00 00 A5 00 00 00");
  // Initialize, then unsolicited "initialization finished", nothing asked.
  EXPECT_EQ(exchange(pair.bus, 1, "08 02 01 00 00 00 00 00"), "1: 08 02 01 00 00 00 00 00");
  EXPECT_EQ(next_frame(pair.bus), "1: 08 02 00 00 00 00 00 00");
  EXPECT_EQ(exchange(pair.bus, 1, "08 02 00 00 00 00 00 00"), "1: 08 02 00 00 01 00 00 00");
  // Force, firmware version, baud rate.
  EXPECT_EQ(exchange(pair.bus, 1, "05 02 01 00 1E 00 00 00"), "1: 05 02 01 00 1E 00 00 00");
  EXPECT_EQ(exchange(pair.bus, 1, "05 02 00 00 00 00 00 00"), "1: 05 02 00 00 1E 00 00 00");
  EXPECT_EQ(exchange(pair.bus, 1, "13 01 00 00 00 00 00 00"), "1: 13 01 00 00 00 02 01 04");
  EXPECT_EQ(exchange(pair.bus, 1, "14 01 01 00 02 00 00 00"), "1: 14 01 01 00 02 00 00 00");
  EXPECT_EQ(exchange(pair.bus, 1, "14 01 00 00 00 00 00 00"), "1: 14 01 00 00 02 00 00 00");
  // Position set and, once arrived, read.
  EXPECT_EQ(exchange(pair.bus, 1, "06 02 01 00 3C 00 00 00"), "1: 06 02 01 00 3C 00 00 00");
  std::string status;
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (status != "1: 0F 01 00 00 02 00 00 00" && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(10ms);  // command pacing, not a wait for time
    status = exchange(pair.bus, 1, "0F 01 00 00 00 00 00 00");
  }
  EXPECT_EQ(status, "1: 0F 01 00 00 02 00 00 00") << "arrived, data-field form (docs/protocol-notes.md reading 2)";
  EXPECT_EQ(exchange(pair.bus, 1, "06 02 00 00 00 00 00 00"), "1: 06 02 00 00 3C 00 00 00");
  // Set the CAN ID to 2 with ID 0: the reply carries ID 0.
  EXPECT_EQ(exchange(pair.bus, 0, "12 01 01 00 02 00 00 00"), "0: 12 01 01 00 02 00 00 00");
}

TEST(CanServer, OnlyTheAddressedHandAnswers) {
  BusPair pair;
  Running running(options_with({hand(1), hand(3)}), once(pair.server));
  ASSERT_TRUE(running.started());
  EXPECT_EQ(exchange(pair.bus, 3, "05 02 01 00 1E 00 00 00"), "3: 05 02 01 00 1E 00 00 00");
  // Nobody is 2: the next frame on the bus is hand 1's answer.
  send_frame(pair.bus, frame_of(2, "13 01 00 00 00 00 00 00"));
  EXPECT_EQ(exchange(pair.bus, 1, "05 02 00 00 00 00 00 00"), "1: 05 02 00 00 32 00 00 00");
}

TEST(CanServer, ForeignFramesAreIgnoredAndCounted) {
  BusPair pair;
  Running running(options_with({hand(1)}), once(pair.server));
  ASSERT_TRUE(running.started());
  const std::string version = "13 01 00 00 00 00 00 00";
  send_frame(pair.bus, frame_of(CAN_EFF_FLAG | 1, version));     // extended
  send_frame(pair.bus, frame_of(CAN_RTR_FLAG | 1, version));     // remote request
  send_frame(pair.bus, frame_of(CAN_ERR_FLAG | 1, version));     // error frame
  send_frame(pair.bus, frame_of(0x101, version));                // ID over 255
  send_frame(pair.bus, frame_of(1, "13 01 00 00 00 00 00"));     // 7 bytes
  send_frame(pair.bus, frame_of(1, "13 01 07 00 00 00 00 00"));  // R/W byte 07
  const char short_datagram[3] = {1, 2, 3};
  ASSERT_EQ(::send(pair.bus, short_datagram, sizeof short_datagram, 0), 3);
  // The first frame on the bus is the answer to the one real request.
  EXPECT_EQ(exchange(pair.bus, 1, version), "1: 13 01 00 00 00 02 01 04");
  running.stop();
  EXPECT_EQ(running.server().counters().foreign_frames, 7u);
  EXPECT_EQ(running.server().counters().frames_received, 1u);
  EXPECT_EQ(running.server().counters().frames_sent, 1u);
}

TEST(CanServer, ControlCommandsWorkAndQuitEndsTheRun) {
  BusPair pair;
  Running running(options_with({hand(1), hand(4)}), once(pair.server));
  ASSERT_TRUE(running.started());
  EXPECT_EQ(running.control("hands"), "ok hands 1 4");
  EXPECT_EQ(running.control("mute 1"), "ok mute 1");
  send_frame(pair.bus, frame_of(1, "13 01 00 00 00 00 00 00"));  // lost
  EXPECT_EQ(exchange(pair.bus, 4, "13 01 00 00 00 00 00 00"), "4: 13 01 00 00 00 02 01 04");
  EXPECT_EQ(running.control("unmute 1"), "ok unmute 1");
  EXPECT_EQ(running.control("corrupt 1 1"), "ok corrupt 1 1");
  EXPECT_EQ(exchange(pair.bus, 1, "13 01 00 00 00 00 00 00"), "1: 13 01 00 00 FF 02 01 04");
  EXPECT_EQ(running.control("kick"), "error unknown command 'kick' (see --help)")
      << "kick is the TCP transport's";
  EXPECT_EQ(running.control("violations"),
            "error the interval check is off (start with --min-interval-ms)");
  EXPECT_EQ(running.control("quit"), "ok quit");
  running.stop();  // returns: run() has ended by itself
}

TEST(CanServer, CountsFramesToOneHandCloserThanTheMinimumInterval) {
  FakeClock clock;
  BusPair pair;
  CanServerOptions options = options_with({hand(1), hand(2)});
  options.min_interval = 20ms;
  options.kernel_timestamps = false;  // the read time, from the fake clock
  Running running(options, once(pair.server), clock);
  ASSERT_TRUE(running.started());
  const std::string version = "13 01 00 00 00 02 01 04";
  EXPECT_EQ(exchange(pair.bus, 1, "13 01 00 00 00 00 00 00"), "1: " + version);
  clock.advance(5ms);
  EXPECT_EQ(exchange(pair.bus, 1, "13 01 00 00 00 00 00 00"), "1: " + version);
  EXPECT_EQ(running.control("violations"), "ok 1");
  EXPECT_EQ(exchange(pair.bus, 2, "13 01 00 00 00 00 00 00"), "2: " + version);
  EXPECT_EQ(running.control("violations"), "ok 1") << "hand 2's first frame";
  clock.advance(25ms);
  EXPECT_EQ(exchange(pair.bus, 1, "13 01 00 00 00 00 00 00"), "1: " + version);
  EXPECT_EQ(running.control("violations"), "ok 1") << "25 ms after the previous one";
  // ID 0 reaches both hands: 0 ms after hand 1's frame, 25 ms after hand 2's.
  send_frame(pair.bus, frame_of(0, "12 01 00 00 00 00 00 00"));
  EXPECT_EQ(next_frame(pair.bus), "0: 12 01 00 00 01 00 00 00");
  EXPECT_EQ(next_frame(pair.bus), "0: 12 01 00 00 02 00 00 00");
  EXPECT_EQ(running.control("violations"), "ok 2");
  // A frame to an ID without a hand counts for nobody.
  send_frame(pair.bus, frame_of(7, "13 01 00 00 00 00 00 00"));
  send_frame(pair.bus, frame_of(7, "13 01 00 00 00 00 00 00"));
  EXPECT_EQ(exchange(pair.bus, 2, "05 02 00 00 00 00 00 00"), "2: 05 02 00 00 32 00 00 00");
  EXPECT_EQ(running.control("violations"), "ok 3") << "only hand 2's frame, 0 ms after ID 0";
  running.stop();
  EXPECT_EQ(running.server().interval_violations(), 3u);
}

/// Two requests to hand 1 with a 10-minute minimum interval, read an hour apart
/// by the fake clock but queued within one round trip of the test; returns the
/// answer to `violations`.
std::string violations_of_two_reads_an_hour_apart(bool kernel_timestamps) {
  FakeClock clock;
  BusPair pair;
  CanServerOptions options = options_with({hand(1)});
  options.min_interval = 10min;
  options.kernel_timestamps = kernel_timestamps;
  Running running(options, once(pair.server), clock);
  EXPECT_TRUE(running.started());
  if (!running.started()) return "<not started>";
  EXPECT_EQ(exchange(pair.bus, 1, "13 01 00 00 00 00 00 00"), "1: 13 01 00 00 00 02 01 04");
  clock.advance(1h);
  EXPECT_EQ(exchange(pair.bus, 1, "13 01 00 00 00 00 00 00"), "1: 13 01 00 00 00 02 01 04");
  return running.control("violations");
}

TEST(CanServer, MeasuresWithTheKernelsReceiveTimestampNotTheReadTime) {
  // The socketpair stamps datagrams as they are queued, like a CAN socket: the
  // stamps are a round trip apart, far less than the minimum.
  BusPair probe;
  const int on = 1;
  if (::setsockopt(probe.server, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0) {
    GTEST_SKIP() << "this kernel has no receive timestamps on AF_UNIX sockets";
  }
  ::close(probe.server);
  EXPECT_EQ(violations_of_two_reads_an_hour_apart(true), "ok 1");
}

TEST(CanServer, ReadTimeIsUsedWhereTheFdHasNoTimestamps) {
  EXPECT_EQ(violations_of_two_reads_an_hour_apart(false), "ok 0") << "an hour apart by the clock";
}

TEST(CanServer, ReopensTheInterfaceWhenItsFdFailsAndTheHandsKeepTheirState) {
  BusPair first;
  BusPair second;
  std::mutex mutex;
  std::deque<Result<int, std::string>> opens;
  opens.emplace_back(first.server);
  opens.emplace_back(fail(std::string("no network interface named 'testcan'")));
  opens.emplace_back(second.server);
  bus::CanSocketOpener opener = [&]() -> Result<UniqueFd, std::string> {
    const std::lock_guard lock(mutex);
    if (opens.empty()) return fail(std::string("no more"));
    Result<int, std::string> next = std::move(opens.front());
    opens.pop_front();
    if (!next) return fail(next.error());
    return UniqueFd(next.value());
  };
  CanServerOptions options = options_with({hand(1)});
  options.reopen_interval = 10ms;
  Running running(options, opener);
  ASSERT_TRUE(running.started());
  EXPECT_EQ(exchange(first.bus, 1, "05 02 01 00 1E 00 00 00"), "1: 05 02 01 00 1E 00 00 00");
  ::close(first.bus);  // the interface goes away
  first.bus = -1;
  // Served again on the second fd (after one failed try), force still 30.
  EXPECT_EQ(exchange(second.bus, 1, "05 02 00 00 00 00 00 00"), "1: 05 02 00 00 1E 00 00 00");
  running.stop();
  EXPECT_EQ(running.server().counters().reopens, 1u);
}

TEST(CanServer, OpeningFailsWithTheOpenersReason) {
  auto opened = CanServer::open(
      options_with({hand(1)}),
      []() -> Result<UniqueFd, std::string> {
        return fail(std::string("no network interface named 'vcan9'"));
      },
      SystemClock::instance());
  ASSERT_FALSE(opened.ok());
  EXPECT_EQ(opened.error(), "no network interface named 'vcan9'");
}

}  // namespace
}  // namespace dh3::sim
