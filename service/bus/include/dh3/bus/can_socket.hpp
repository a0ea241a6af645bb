#pragma once
// The CAN_RAW socket DH-3 hands are reached through, the same for dh3-service's
// socketcan bus and dh3-sim's CAN server: bound to an interface such as can0,
// with a kernel receive filter for what DH-3 hands send (standard 11-bit data
// frames with IDs 0-kMaxHandCanId) plus the controller's error frames.

#include <cstdint>
#include <functional>
#include <string>

#include "dh3/base/fd_util.hpp"
#include "dh3/base/result.hpp"

namespace dh3::bus {

/// DH-3 hands use CAN IDs 0-255 (spec: "Gripper ID ... range 0-255"); the
/// kernel filter passes no other, and what reads the socket checks it again.
inline constexpr std::uint32_t kMaxHandCanId = 0xFF;

/// Returns a fresh non-blocking fd carrying `struct can_frame` datagrams, or
/// why it could not: open_can_raw_socket() for a real interface; in tests one
/// end of an AF_UNIX socketpair.
using CanSocketOpener = std::function<Result<UniqueFd, std::string>()>;

/// Empty if the kernel can create PF_CAN sockets, else the reason, e.g.
/// "kernel has no CAN support: socket(PF_CAN) failed: Address family not
/// supported by protocol".
[[nodiscard]] std::string kernel_can_support_problem();

/// Why `interface` will not carry CAN frames however long one waits, or empty:
/// no CAN support in the kernel, a name no interface can have, or an existing
/// interface that is not CAN. A missing or down interface may still come.
[[nodiscard]] std::string lasting_can_interface_problem(const std::string& interface);

/// socket(PF_CAN, SOCK_RAW, CAN_RAW), receive filter, error-frame mask,
/// SO_RXQ_OVFL, bind to
/// `interface`. Fails with a clear reason when the interface is missing, is not
/// a CAN interface, or is down.
[[nodiscard]] Result<UniqueFd, std::string> open_can_raw_socket(const std::string& interface);

}  // namespace dh3::bus
