#include <fcntl.h>
#include <sys/file.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <optional>
#include <utility>

#include "dh3/bus/stream_link.hpp"

namespace dh3::bus {
namespace {

struct BaudConstant {
  std::uint32_t rate;
  speed_t constant;
};

constexpr std::array<BaudConstant, 21> kBaudConstants{{
    {1200, B1200},       {2400, B2400},       {4800, B4800},       {9600, B9600},
    {19200, B19200},     {38400, B38400},     {57600, B57600},     {115200, B115200},
    {230400, B230400},   {460800, B460800},   {500000, B500000},   {576000, B576000},
    {921600, B921600},   {1000000, B1000000}, {1152000, B1152000}, {1500000, B1500000},
    {2000000, B2000000}, {2500000, B2500000}, {3000000, B3000000}, {3500000, B3500000},
    {4000000, B4000000},
}};

constexpr std::array<std::uint32_t, kBaudConstants.size()> kBaudRates = [] {
  std::array<std::uint32_t, kBaudConstants.size()> rates{};
  for (std::size_t i = 0; i < rates.size(); ++i) rates[i] = kBaudConstants[i].rate;
  return rates;
}();

std::optional<speed_t> speed_constant(std::uint32_t rate) {
  for (const auto& entry : kBaudConstants) {
    if (entry.rate == rate) return entry.constant;
  }
  return std::nullopt;
}

}  // namespace

std::span<const std::uint32_t> supported_baud_rates() {
  return kBaudRates;
}

bool is_supported_baud_rate(std::uint32_t baud_rate) {
  return speed_constant(baud_rate).has_value();
}

SerialLink::SerialLink(std::string path, std::uint32_t baud_rate)
    : path_(std::move(path)), baud_rate_(baud_rate) {}

std::string SerialLink::describe() const {
  return "serial " + path_ + " @ " + std::to_string(baud_rate_);
}

Result<OpenStarted, std::string> SerialLink::start_open() {
  const auto speed = speed_constant(baud_rate_);
  if (!speed) return dh3::fail("unsupported baud rate " + std::to_string(baud_rate_));
  // O_NOCTTY: the device must never become the service's controlling terminal.
  UniqueFd fd(::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
  if (!fd) return dh3::fail("open " + path_ + ": " + errno_text(errno));
  if (::isatty(fd.get()) == 0) return dh3::fail(path_ + " is not a serial device (not a tty)");
  if (::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) {
    if (errno == EWOULDBLOCK) return dh3::fail(path_ + " is in use by another process (locked)");
    return dh3::fail("flock " + path_ + ": " + errno_text(errno));
  }

  termios tty{};
  if (::tcgetattr(fd.get(), &tty) != 0)
    return dh3::fail("tcgetattr " + path_ + ": " + errno_text(errno));
  ::cfmakeraw(&tty);  // no echo, no line editing, no CR/LF translation, 8 bits
  tty.c_cflag &= ~static_cast<tcflag_t>(PARENB | CSTOPB | CSIZE | CRTSCTS);
  tty.c_cflag |= CS8 | CREAD | CLOCAL;  // CLOCAL: no modem lines to wait for
  tty.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  // VMIN 1 / VTIME 0 with O_NONBLOCK: a read with nothing to read fails with
  // EAGAIN. (VMIN 0 would return 0, which is indistinguishable from a hangup.)
  // poll() does all the waiting.
  tty.c_cc[VMIN] = 1;
  tty.c_cc[VTIME] = 0;
  if (::cfsetispeed(&tty, *speed) != 0 || ::cfsetospeed(&tty, *speed) != 0) {
    return dh3::fail("cfsetspeed " + std::to_string(baud_rate_) + ": " + errno_text(errno));
  }
  if (::tcsetattr(fd.get(), TCSANOW, &tty) != 0) {
    return dh3::fail("tcsetattr " + path_ + ": " + errno_text(errno));
  }
  // Bytes that sat in the driver before we owned the line belong to no request.
  ::tcflush(fd.get(), TCIOFLUSH);
  return OpenStarted{std::move(fd), false};
}

Result<void, std::string> SerialLink::finish_open(int /*fd*/) {
  return {};
}

ssize_t SerialLink::write_some(int fd, std::span<const std::uint8_t> bytes) {
  return ::write(fd, bytes.data(), bytes.size());
}

ssize_t SerialLink::read_some(int fd, std::span<std::uint8_t> bytes) {
  return ::read(fd, bytes.data(), bytes.size());
}

}  // namespace dh3::bus
