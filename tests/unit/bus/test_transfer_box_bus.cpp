// TransferBoxBus against a transfer box played by the test: a TCP server on
// 127.0.0.1 (port 0) and the master side of a pty for the serial line.

#include <arpa/inet.h>
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <future>
#include <string>
#include <vector>

#include "dh3/bus/bus_spec.hpp"
#include "dh3/bus/transfer_box_bus.hpp"
#include "dh3/protocol/codec.hpp"
#include "support/bus_wait.hpp"

namespace dh3::bus {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;
using protocol::make_read;
using protocol::make_write;
namespace reg = protocol::reg;

Bytes box_bytes(const protocol::Message& message) {
  const auto frame = protocol::encode_box_frame(message);
  return Bytes(frame.begin(), frame.end());
}

Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes all;
  for (const auto& part : parts) all.insert(all.end(), part.begin(), part.end());
  return all;
}

/// Reads from `fd` until `count` bytes arrived or 10 s passed, calling
/// `between` (e.g. bus.receive, which flushes the bus's send buffer) between reads.
Bytes read_bytes(int fd, std::size_t count, const std::function<void()>& between = {}) {
  Bytes got;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (got.size() < count && std::chrono::steady_clock::now() < until) {
    if (between) between();
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, between ? 1 : 20) <= 0) continue;
    std::uint8_t buffer[4096];
    const ssize_t n = ::read(fd, buffer, std::min(sizeof buffer, count - got.size()));
    if (n <= 0) break;
    got.insert(got.end(), buffer, buffer + n);
  }
  return got;
}

void write_bytes(int fd, const Bytes& bytes) {
  ASSERT_EQ(::write(fd, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
}

/// A transfer box on 127.0.0.1: listens, accepts one connection at a time.
class BoxServer {
 public:
  /// Port 0 picks a free port; a given port is reused (SO_REUSEADDR) so a test
  /// can bring "the same box" back.
  explicit BoxServer(std::uint16_t port = 0, int backlog = 4) {
    listener_.reset(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
    const int on = 1;
    ::setsockopt(listener_.get(), SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = htons(port);
    if (::bind(listener_.get(), reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        ::listen(listener_.get(), backlog) != 0) {
      ADD_FAILURE() << "cannot listen on 127.0.0.1:" << port << ": " << errno_text(errno);
      return;
    }
    socklen_t length = sizeof address;
    ::getsockname(listener_.get(), reinterpret_cast<sockaddr*>(&address), &length);
    port_ = ntohs(address.sin_port);
  }

  [[nodiscard]] std::uint16_t port() const { return port_; }
  [[nodiscard]] std::string spec() const { return "tcp:127.0.0.1:" + std::to_string(port_); }
  [[nodiscard]] int connection() const { return connection_.get(); }

  /// Waits up to 10 s for the bus to connect.
  bool accept() {
    pollfd p{listener_.get(), POLLIN, 0};
    if (::poll(&p, 1, 10000) <= 0) return false;
    connection_.reset(::accept4(listener_.get(), nullptr, nullptr, SOCK_CLOEXEC));
    return connection_.valid();
  }
  void send(const Bytes& bytes) { write_bytes(connection_.get(), bytes); }
  Bytes read(std::size_t count, const std::function<void()>& between = {}) {
    return read_bytes(connection_.get(), count, between);
  }
  void close_connection() { connection_.reset(); }
  void close_all() {
    connection_.reset();
    listener_.reset();
  }

 private:
  UniqueFd listener_;
  UniqueFd connection_;
  std::uint16_t port_ = 0;
};

TransferBoxOptions fast_reconnect() {
  TransferBoxOptions options;
  options.reconnect.initial_backoff = 10ms;
  options.reconnect.max_backoff = 100ms;
  return options;
}

std::unique_ptr<TransferBoxBus> tcp_bus(const BoxServer& server, const Clock& clock,
                                        TransferBoxOptions options = fast_reconnect()) {
  return std::make_unique<TransferBoxBus>(
      server.spec(), std::make_unique<TcpLink>("127.0.0.1", server.port()), clock, options);
}

// ---- TCP ----

TEST(TransferBoxTcp, SendPutsTheDocumentsExactBytesOnTheWire) {
  BoxServer server;
  auto bus = tcp_bus(server, SystemClock::instance());
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::up));
  ASSERT_TRUE(server.accept());

  ASSERT_TRUE(bus->send(test::to_can_frame(make_write(1, reg::kPosition, 60))).ok());
  ASSERT_TRUE(bus->send(test::to_can_frame(make_read(2, reg::kFirmwareVersion))).ok());
  ASSERT_TRUE(bus->send(test::to_can_frame(make_write(255, reg::kInitialize, 1))).ok());
  const Bytes seen = server.read(42);
  // spec "Position": set 60 %; "Firmware version": read; then hand 255 initializing.
  const Bytes expected{0xFF, 0xFE, 0xFD, 0xFC, 0x01, 0x06, 0x02, 0x01, 0x00, 0x3C, 0x00,
                       0x00, 0x00, 0xFB, 0xFF, 0xFE, 0xFD, 0xFC, 0x02, 0x13, 0x01, 0x00,
                       0x00, 0x00, 0x00, 0x00, 0x00, 0xFB, 0xFF, 0xFE, 0xFD, 0xFC, 0xFF,
                       0x08, 0x02, 0x01, 0x00, 0x01, 0x00, 0x00, 0x00, 0xFB};
  EXPECT_EQ(seen, expected);
  EXPECT_EQ(bus->counters().frames_sent, 3u);
}

TEST(TransferBoxTcp, RejectsFramesTheBoxCannotCarry) {
  BoxServer server;
  auto bus = tcp_bus(server, SystemClock::instance());
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::up));
  ASSERT_TRUE(server.accept());

  CanFrame frame = test::to_can_frame(make_read(1, reg::kPosition));
  frame.id = 256;  // the box's gripper-ID byte holds 0-255
  EXPECT_EQ(bus->send(frame).error(), BusError::frame_invalid);
  frame.id = 1;
  frame.length = 7;
  EXPECT_EQ(bus->send(frame).error(), BusError::frame_invalid);
  frame.length = 8;
  frame.data[2] = 0x02;  // read/write byte must be 00 or 01
  EXPECT_EQ(bus->send(frame).error(), BusError::frame_invalid);
  frame.data[2] = 0x00;
  frame.id = 0;  // ID 0 is legal: "whichever hand is there"
  ASSERT_TRUE(bus->send(frame).ok());
  EXPECT_EQ(server.read(14), box_bytes(make_read(0, reg::kPosition)));
}

TEST(TransferBoxTcp, ReceivesExactlyTheFramesInASplitStreamWithGarbage) {
  BoxServer server;
  auto bus = tcp_bus(server, SystemClock::instance());
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::up));
  ASSERT_TRUE(server.accept());

  const auto a = make_write(1, reg::kPosition, 60);
  const auto b = make_read(2, reg::kGripStatus);
  const auto c = protocol::Message{3, reg::kFirmwareVersion, protocol::Access::read, 0, 0x04010200};
  const auto d = make_write(4, reg::kRotation, -1);  // data is signed 32-bit
  Bytes bad_access = box_bytes(make_read(9, reg::kPosition));
  bad_access[7] = 0x02;
  const Bytes b_bytes = box_bytes(b);
  std::vector<Bytes> writes{
      {0xFB, 0x00, 0xFF, 0xFE, 0xFD},  // a lone end byte, a truncated header
      box_bytes(a),
      {0x11, 0xFF, 0xFF},
      Bytes(b_bytes.begin(), b_bytes.begin() + 3),  // b split three ways
      Bytes(b_bytes.begin() + 3, b_bytes.begin() + 9),
      Bytes(b_bytes.begin() + 9, b_bytes.end()),
      bad_access,  // header and end in place, invalid read/write byte
      concat({box_bytes(c), {0xFB, 0xFB}, box_bytes(d)}),  // two frames in one write
  };
  std::vector<CanFrame> frames;
  for (const Bytes& piece : writes) {
    server.send(piece);
    (void)bus->receive(frames, 5ms);  // let the bus see the pieces one by one
  }
  const auto rest = test::receive_frames(*bus, 4 - std::min<std::size_t>(4, frames.size()));
  frames.insert(frames.end(), rest.begin(), rest.end());

  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[0], test::to_can_frame(a));
  EXPECT_EQ(frames[1], test::to_can_frame(b));
  EXPECT_EQ(frames[2], test::to_can_frame(c));
  EXPECT_EQ(frames[3], test::to_can_frame(d));
  // The version reply as the document prints it: data bytes 00 02 01 04.
  EXPECT_EQ(frames[2].data,
            (std::array<std::uint8_t, 8>{0x13, 0x01, 0x00, 0x00, 0x00, 0x02, 0x01, 0x04}));
  EXPECT_EQ(bus->counters().frames_received, 4u);
  EXPECT_GT(bus->counters().bytes_skipped, 0u);
}

TEST(TransferBoxTcp, ServerClosingIsLinkDownAfterTheFramesItSent) {
  BoxServer server;
  auto bus = tcp_bus(server, SystemClock::instance());
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::up));
  ASSERT_TRUE(server.accept());

  const auto reply = make_write(1, reg::kPosition, 60);
  server.send(box_bytes(reply));
  server.close_all();

  std::vector<CanFrame> frames;
  Result<void, BusError> last;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < until) {
    last = bus->receive(frames, 20ms);
    if (!last.ok()) break;
  }
  ASSERT_FALSE(last.ok());
  EXPECT_EQ(last.error(), BusError::link_down);
  EXPECT_EQ(bus->link_state(), LinkState::down);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0], test::to_can_frame(reply));
  EXPECT_EQ(bus->send(test::to_can_frame(reply)).error(), BusError::link_down);
  EXPECT_EQ(bus->counters().link_drops, 1u);
}

TEST(TransferBoxTcp, ReconnectsWhenTheBoxComesBackOnTheSamePort) {
  auto server = std::make_unique<BoxServer>();
  const std::uint16_t port = server->port();
  auto bus = tcp_bus(*server, SystemClock::instance());
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::up));
  ASSERT_TRUE(server->accept());

  server->close_all();
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::down));
  // A few failed attempts while nobody listens.
  std::vector<CanFrame> frames;
  const auto attempts_when_down = bus->counters().open_attempts;
  test::receive_until(
      *bus, [&](const auto&) { return bus->counters().open_attempts >= attempts_when_down + 2; });
  ASSERT_GE(bus->counters().open_attempts, attempts_when_down + 2);
  EXPECT_EQ(bus->link_state(), LinkState::down);

  server = std::make_unique<BoxServer>(port);
  ASSERT_EQ(server->port(), port);
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::up));
  ASSERT_TRUE(server->accept());
  const auto request = make_read(1, reg::kPosition);
  ASSERT_TRUE(bus->send(test::to_can_frame(request)).ok());
  EXPECT_EQ(server->read(14), box_bytes(request));
  server->send(box_bytes(protocol::Message{1, reg::kPosition, protocol::Access::read, 0, 42}));
  const auto received = test::receive_frames(*bus, 1);
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received[0].id, 1u);
  EXPECT_EQ(received[0].data[4], 42);
  EXPECT_EQ(bus->counters().link_drops, 1u);
}

TEST(TransferBoxTcp, ConnectToAClosedPortIsLinkDownAtOnce) {
  std::uint16_t closed_port = 0;
  {
    BoxServer probe;  // take a free port, then free it: nobody listens there
    closed_port = probe.port();
  }
  TransferBoxOptions options;
  options.reconnect.initial_backoff = 1h;  // one attempt only
  TransferBoxBus bus("tcp:127.0.0.1:" + std::to_string(closed_port),
                     std::make_unique<TcpLink>("127.0.0.1", closed_port), SystemClock::instance(),
                     options);
  std::vector<CanFrame> frames;
  // The refused connect ends the attempt; receive() says link_down (it may take
  // a second call if the refusal arrives after the first poll).
  Result<void, BusError> last = bus.receive(frames, 20ms);
  if (last.ok()) last = bus.receive(frames, 20ms);
  ASSERT_FALSE(last.ok());
  EXPECT_EQ(last.error(), BusError::link_down);
  EXPECT_EQ(bus.link_state(), LinkState::down);
  EXPECT_EQ(bus.counters().open_attempts, 1u);
  EXPECT_EQ(bus.send(CanFrame{}).error(), BusError::link_down);
}

TEST(TransferBoxTcp, AConnectThatNeverCompletesTimesOut) {
  // A listener with a full accept queue drops new SYNs, so a connect stays in
  // progress: the bus must give up after connect_timeout (on its clock).
  BoxServer server(0, 0);
  UniqueFd filler(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(server.port());
  ASSERT_EQ(::connect(filler.get(), reinterpret_cast<sockaddr*>(&address), sizeof address), 0);

  FakeClock clock;
  TransferBoxOptions options;
  options.connect_timeout = 2s;
  options.reconnect.initial_backoff = 1h;
  TransferBoxBus bus(server.spec(), std::make_unique<TcpLink>("127.0.0.1", server.port()), clock,
                     options);
  std::vector<CanFrame> frames;
  EXPECT_EQ(bus.receive(frames, 50ms).error(), BusError::link_down);
  if (bus.link_state() == LinkState::up) {
    GTEST_SKIP() << "this kernel completed a connect to a listener with a full accept queue";
  }
  EXPECT_EQ(bus.counters().open_attempts, 1u);
  clock.advance(2s);
  EXPECT_EQ(bus.receive(frames, 0ms).error(), BusError::link_down);
  EXPECT_EQ(bus.link_state(), LinkState::down);
  // Still one attempt: it was abandoned, and the next waits for the backoff.
  EXPECT_EQ(bus.receive(frames, 0ms).error(), BusError::link_down);
  EXPECT_EQ(bus.counters().open_attempts, 1u);
}

TEST(TransferBoxTcp, ReconnectAttemptsBackOffExponentially) {
  std::uint16_t closed_port = 0;
  {
    BoxServer probe;
    closed_port = probe.port();
  }
  FakeClock clock;
  TransferBoxOptions options;
  options.reconnect.initial_backoff = 100ms;
  options.reconnect.max_backoff = 5s;
  TransferBoxBus bus("tcp", std::make_unique<TcpLink>("127.0.0.1", closed_port), clock, options);
  std::vector<CanFrame> frames;
  (void)bus.receive(frames, 5ms);  // lets the first (refused) attempt finish
  (void)bus.receive(frames, 5ms);
  ASSERT_EQ(bus.counters().open_attempts, 1u);
  ASSERT_EQ(bus.link_state(), LinkState::down);

  // The waits double from 100 ms and stop growing at 5 s.
  std::uint64_t expected_attempts = 1;
  for (const auto wait : {100ms, 200ms, 400ms, 800ms, 1600ms, 3200ms, 5000ms, 5000ms}) {
    clock.advance(wait - 1ms);
    (void)bus.receive(frames, 5ms);  // also lets a refused connect finish
    (void)bus.receive(frames, 5ms);
    EXPECT_EQ(bus.counters().open_attempts, expected_attempts) << "early retry at " << wait.count();
    clock.advance(1ms);
    (void)bus.receive(frames, 5ms);
    (void)bus.receive(frames, 5ms);
    ++expected_attempts;
    EXPECT_EQ(bus.counters().open_attempts, expected_attempts) << "no retry after " << wait.count();
  }
  EXPECT_EQ(bus.link_state(), LinkState::down);
}

TEST(TransferBoxTcp, WakeEndsAReceiveThatWaitsForTheNextAttempt) {
  std::uint16_t closed_port = 0;
  {
    BoxServer probe;
    closed_port = probe.port();
  }
  TransferBoxOptions options;
  options.reconnect.initial_backoff = 1h;
  TransferBoxBus bus("tcp", std::make_unique<TcpLink>("127.0.0.1", closed_port),
                     SystemClock::instance(), options);
  ASSERT_TRUE(test::wait_for_link(bus, LinkState::down));
  auto waiting = std::async(std::launch::async, [&bus] {
    std::vector<CanFrame> frames;
    return bus.receive(frames, std::chrono::minutes(2)).error();
  });
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (waiting.wait_for(10ms) != std::future_status::ready &&
         std::chrono::steady_clock::now() < until) {
    bus.wake();
  }
  ASSERT_EQ(waiting.wait_for(0s), std::future_status::ready) << "wake() did not end receive()";
  EXPECT_EQ(waiting.get(), BusError::link_down);
}

TEST(TransferBoxTcp, WakeEndsAReceiveOnALiveLink) {
  BoxServer server;
  auto bus = tcp_bus(server, SystemClock::instance());
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::up));
  ASSERT_TRUE(server.accept());
  auto waiting = std::async(std::launch::async, [&bus] {
    std::vector<CanFrame> frames;
    return bus->receive(frames, std::chrono::minutes(2)).ok() && frames.empty();
  });
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (waiting.wait_for(10ms) != std::future_status::ready &&
         std::chrono::steady_clock::now() < until) {
    bus->wake();
  }
  ASSERT_EQ(waiting.wait_for(0s), std::future_status::ready) << "wake() did not end receive()";
  EXPECT_TRUE(waiting.get());
}

TEST(TransferBoxTcp, AFullSendBufferSaysWouldBlockAndDrainsLater) {
  BoxServer server;
  TransferBoxOptions options = fast_reconnect();
  options.send_buffer_limit = 10 * 14;
  auto bus = tcp_bus(server, SystemClock::instance(), options);
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::up));
  ASSERT_TRUE(server.accept());

  // The box does not read: the kernel buffers fill, then the bus's own.
  std::size_t accepted = 0;
  Result<void, BusError> last;
  for (std::size_t i = 0; i < 2'000'000; ++i) {
    const auto message = make_write(static_cast<std::uint8_t>(i % 200 + 1), reg::kPosition,
                                    static_cast<std::int32_t>(i % 101));
    last = bus->send(test::to_can_frame(message));
    if (!last.ok()) break;
    ++accepted;
  }
  ASSERT_FALSE(last.ok());
  ASSERT_EQ(last.error(), BusError::would_block);
  EXPECT_EQ(bus->link_state(), LinkState::up);

  // Once the box reads, later receive() calls flush the rest: every accepted
  // frame arrives, whole and in order.
  std::vector<CanFrame> ignored;
  const Bytes seen = server.read(accepted * 14, [&] { (void)bus->receive(ignored, 0ms); });
  ASSERT_EQ(seen.size(), accepted * 14);
  for (std::size_t i = 0; i < accepted; ++i) {
    const auto message = make_write(static_cast<std::uint8_t>(i % 200 + 1), reg::kPosition,
                                    static_cast<std::int32_t>(i % 101));
    const Bytes expected = box_bytes(message);
    ASSERT_TRUE(std::equal(expected.begin(), expected.end(),
                           seen.begin() + static_cast<std::ptrdiff_t>(i * 14)))
        << "frame " << i << " of " << accepted;
  }
  EXPECT_TRUE(bus->send(test::to_can_frame(make_read(1, reg::kPosition))).ok());
}

// ---- serial, over a pty: the test is the box on the master side ----

class Pty {
 public:
  Pty() {
    master_.reset(::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC));
    if (!master_ || ::grantpt(master_.get()) != 0 || ::unlockpt(master_.get()) != 0) {
      ADD_FAILURE() << "cannot create a pty: " << errno_text(errno);
      return;
    }
    char name[128] = {};
    if (::ptsname_r(master_.get(), name, sizeof name) != 0) {
      ADD_FAILURE() << "ptsname_r: " << errno_text(errno);
      return;
    }
    slave_path_ = name;
  }
  [[nodiscard]] int master() const { return master_.get(); }
  [[nodiscard]] const std::string& slave_path() const { return slave_path_; }
  void close() { master_.reset(); }

 private:
  UniqueFd master_;
  std::string slave_path_;
};

TEST(TransferBoxSerial, ExchangesFramesOverTheSerialSpec) {
  Pty pty;
  auto opened = open_bus("serial:" + pty.slave_path() + "@115200", SystemClock::instance());
  ASSERT_TRUE(opened.ok()) << opened.error();
  Bus& bus = *opened.value();
  ASSERT_TRUE(test::wait_for_link(bus, LinkState::up));

  // spec "Initialization": FF FE FD FC 01 08 02 01 00 00 00 00 00 FB
  ASSERT_TRUE(bus.send(test::to_can_frame(make_write(1, reg::kInitialize, 0))).ok());
  EXPECT_EQ(read_bytes(pty.master(), 14), (Bytes{0xFF, 0xFE, 0xFD, 0xFC, 0x01, 0x08, 0x02, 0x01,
                                                 0x00, 0x00, 0x00, 0x00, 0x00, 0xFB}));

  const auto echo = make_write(1, reg::kInitialize, 0);
  const auto done = protocol::Message{1, reg::kInitialize, protocol::Access::read, 0, 1};
  const Bytes stream = concat({{0x00, 0xFB}, box_bytes(echo), {0xFF, 0xFE}, box_bytes(done)});
  write_bytes(pty.master(), Bytes(stream.begin(), stream.begin() + 9));
  std::vector<CanFrame> frames;
  (void)bus.receive(frames, 5ms);
  write_bytes(pty.master(), Bytes(stream.begin() + 9, stream.end()));
  const auto rest = test::receive_frames(bus, 2 - std::min<std::size_t>(2, frames.size()));
  frames.insert(frames.end(), rest.begin(), rest.end());
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0], test::to_can_frame(echo));
  EXPECT_EQ(frames[1], test::to_can_frame(done));
}

TEST(TransferBoxSerial, UnpluggedDeviceIsLinkDownAndIsReopenedWhenBack) {
  // The bus opens a stable name (like /dev/serial/by-id/...) that the test
  // points at a new pty when "the device is plugged in again".
  const auto dir =
      std::filesystem::temp_directory_path() / ("dh3-serial-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto link_path = dir / "ttyBOX";
  auto point_at = [&](const std::string& target) {
    const auto temporary = dir / "ttyBOX.new";
    std::filesystem::remove(temporary);
    std::filesystem::create_symlink(target, temporary);
    std::filesystem::rename(temporary, link_path);  // atomic replace
  };

  auto first = std::make_unique<Pty>();
  point_at(first->slave_path());
  OpenBusOptions options;
  options.transfer_box = fast_reconnect();
  auto opened =
      open_bus("serial:" + link_path.string() + "@9600", SystemClock::instance(), options);
  ASSERT_TRUE(opened.ok()) << opened.error();
  auto& bus = dynamic_cast<TransferBoxBus&>(*opened.value());
  ASSERT_TRUE(test::wait_for_link(bus, LinkState::up));

  first->close();  // unplugged
  ASSERT_TRUE(test::wait_for_link(bus, LinkState::down));
  EXPECT_EQ(bus.send(test::to_can_frame(make_read(1, reg::kPosition))).error(),
            BusError::link_down);
  const auto attempts_when_down = bus.counters().open_attempts;
  test::receive_until(
      bus, [&](const auto&) { return bus.counters().open_attempts >= attempts_when_down + 2; });
  EXPECT_EQ(bus.link_state(), LinkState::down);  // the name points nowhere

  Pty second;
  point_at(second.slave_path());
  ASSERT_TRUE(test::wait_for_link(bus, LinkState::up));
  const auto request = make_read(1, reg::kPosition);
  ASSERT_TRUE(bus.send(test::to_can_frame(request)).ok());
  EXPECT_EQ(read_bytes(second.master(), 14), box_bytes(request));
  const auto reply = protocol::Message{1, reg::kPosition, protocol::Access::read, 0, 60};
  write_bytes(second.master(), box_bytes(reply));
  const auto frames = test::receive_frames(bus, 1);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0], test::to_can_frame(reply));
  EXPECT_EQ(bus.counters().link_drops, 1u);

  std::filesystem::remove_all(dir);
}

TEST(TransferBoxSerial, ADeviceInUseOrNotATerminalStaysDown) {
  Pty pty;
  TransferBoxOptions options;
  options.reconnect.initial_backoff = 1h;
  TransferBoxBus owner("serial", std::make_unique<SerialLink>(pty.slave_path(), 115200),
                       SystemClock::instance(), options);
  ASSERT_EQ(owner.link_state(), LinkState::up);
  TransferBoxBus second("serial", std::make_unique<SerialLink>(pty.slave_path(), 115200),
                        SystemClock::instance(), options);
  EXPECT_EQ(second.link_state(), LinkState::down);  // locked by the first

  SerialLink not_a_tty("/dev/null", 9600);
  auto attempt = not_a_tty.start_open();
  ASSERT_FALSE(attempt.ok());
  EXPECT_THAT(attempt.error(), ::testing::HasSubstr("not a serial device"));
  SerialLink locked(pty.slave_path(), 9600);
  attempt = locked.start_open();
  ASSERT_FALSE(attempt.ok());
  EXPECT_THAT(attempt.error(), ::testing::HasSubstr("in use by another process"));
  SerialLink odd_rate(pty.slave_path(), 12345);
  attempt = odd_rate.start_open();
  ASSERT_FALSE(attempt.ok());
  EXPECT_THAT(attempt.error(), ::testing::HasSubstr("unsupported baud rate 12345"));
}

}  // namespace
}  // namespace dh3::bus
