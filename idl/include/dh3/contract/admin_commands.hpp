#pragma once
// Which commands are administrative: they change how a hand is reached (its
// CAN ID, its baud rate) and take effect after a reboot. They travel on a
// topic of their own (idl/dh3.idl, topics::ADMIN_REQUEST), so that under DDS
// Security the permissions of that topic decide who may send them.

#include "dh3/contract/dh3.h"

namespace dh3::contract {

[[nodiscard]] constexpr bool is_administrative(msg::CommandType command) {
  return command == msg::SET_CAN_ID || command == msg::SET_BAUD_RATE;
}

}  // namespace dh3::contract
