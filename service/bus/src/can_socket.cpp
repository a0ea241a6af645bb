#include "dh3/bus/can_socket.hpp"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <net/if_arp.h>
#include <sys/ioctl.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace dh3::bus {
namespace {

Result<UniqueFd, std::string> new_can_socket() {
  UniqueFd fd(::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW));
  if (fd) return fd;
  const int error = errno;
  if (error == EAFNOSUPPORT || error == EPROTONOSUPPORT) {
    return dh3::fail("kernel has no CAN support: socket(PF_CAN) failed: " + errno_text(error));
  }
  return dh3::fail("socket(PF_CAN) failed: " + errno_text(error));
}

bool fill_ifreq(ifreq& request, const std::string& interface) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) return false;
  std::memset(&request, 0, sizeof request);
  std::memcpy(request.ifr_name, interface.data(), interface.size());
  return true;
}

std::string bad_name(const std::string& interface) {
  return "invalid interface name '" + interface + "' (1-" + std::to_string(IFNAMSIZ - 1) +
         " characters)";
}

/// The interface's index, or why there is none.
Result<int, std::string> interface_index(int fd, const std::string& interface) {
  ifreq request{};
  if (!fill_ifreq(request, interface)) return dh3::fail(bad_name(interface));
  if (::ioctl(fd, SIOCGIFINDEX, &request) != 0) {
    if (errno == ENODEV) return dh3::fail("no network interface named '" + interface + "'");
    return dh3::fail("SIOCGIFINDEX " + interface + ": " + errno_text(errno));
  }
  return request.ifr_ifindex;
}

/// Empty if `interface` is a CAN interface, else why not.
std::string not_can_reason(int fd, const std::string& interface) {
  ifreq request{};
  if (!fill_ifreq(request, interface)) return bad_name(interface);
  if (::ioctl(fd, SIOCGIFHWADDR, &request) != 0) {
    return "SIOCGIFHWADDR " + interface + ": " + errno_text(errno);
  }
  if (request.ifr_hwaddr.sa_family != ARPHRD_CAN) {
    return "'" + interface + "' is not a CAN interface";
  }
  return {};
}

}  // namespace

std::string kernel_can_support_problem() {
  auto probe = new_can_socket();
  return probe ? std::string() : probe.error();
}

std::string lasting_can_interface_problem(const std::string& interface) {
  auto probe = new_can_socket();
  if (!probe) return probe.error();
  ifreq request{};
  if (!fill_ifreq(request, interface)) return bad_name(interface);
  // An existing interface of another kind will not turn into CAN by waiting.
  if (interface_index(probe.value().get(), interface)) {
    return not_can_reason(probe.value().get(), interface);
  }
  return {};
}

Result<UniqueFd, std::string> open_can_raw_socket(const std::string& interface) {
  auto created = new_can_socket();
  if (!created) return created;
  UniqueFd fd = std::move(created.value());

  const auto index = interface_index(fd.get(), interface);
  if (!index) return dh3::fail(index.error());
  if (auto reason = not_can_reason(fd.get(), interface); !reason.empty()) {
    return dh3::fail(std::move(reason));
  }
  ifreq flags{};
  fill_ifreq(flags, interface);
  if (::ioctl(fd.get(), SIOCGIFFLAGS, &flags) != 0) {
    return dh3::fail("SIOCGIFFLAGS " + interface + ": " + errno_text(errno));
  }
  if ((flags.ifr_flags & IFF_UP) == 0) {
    return dh3::fail("interface '" + interface + "' is down (ip link set " + interface + " up)");
  }

  // Standard data frames with ids 0-0xFF only: the id bits above 0xFF, the
  // extended-frame flag and the RTR flag must all be 0.
  const can_filter filter{0, CAN_EFF_FLAG | CAN_RTR_FLAG | (CAN_SFF_MASK & ~kMaxHandCanId)};
  if (::setsockopt(fd.get(), SOL_CAN_RAW, CAN_RAW_FILTER, &filter, sizeof filter) != 0) {
    return dh3::fail("CAN_RAW_FILTER: " + errno_text(errno));
  }
  // Every class the controller reports: counted by kind, the chatty ones
  // (bus errors come only with berr-reporting on) logged at a limited rate.
  const can_err_mask_t errors = CAN_ERR_MASK;
  if (::setsockopt(fd.get(), SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errors, sizeof errors) != 0) {
    return dh3::fail("CAN_RAW_ERR_FILTER: " + errno_text(errno));
  }
  // Each datagram then carries how many the kernel dropped for a full queue.
  const int on = 1;
  if (::setsockopt(fd.get(), SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on) != 0) {
    return dh3::fail("SO_RXQ_OVFL: " + errno_text(errno));
  }

  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = index.value();
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    return dh3::fail("bind to " + interface + ": " + errno_text(errno));
  }
  return fd;
}

}  // namespace dh3::bus
