#include "dh3/contract/names.hpp"

#include <cstdint>

namespace dh3::contract {

std::string command_name(msg::CommandType command) {
  switch (command) {
    case msg::INITIALIZE:
      return "INITIALIZE";
    case msg::MOVE:
      return "MOVE";
    case msg::SET_CLOSING_FORCE:
      return "SET_CLOSING_FORCE";
    case msg::SET_OPENING_FORCE:
      return "SET_OPENING_FORCE";
    case msg::ROTATE:
      return "ROTATE";
    case msg::READ_REGISTER:
      return "READ_REGISTER";
    case msg::SET_CAN_ID:
      return "SET_CAN_ID";
    case msg::SET_BAUD_RATE:
      return "SET_BAUD_RATE";
    case msg::ENABLE_INIT_FEEDBACK:
      return "ENABLE_INIT_FEEDBACK";
    case msg::GRASP:
      return "GRASP";
    case msg::RELEASE:
      return "RELEASE";
    case msg::STOP:
      return "STOP";
    case msg::SCAN:
      return "SCAN";
    case msg::ACQUIRE_LEASE:
      return "ACQUIRE_LEASE";
    case msg::RENEW_LEASE:
      return "RENEW_LEASE";
    case msg::RELEASE_LEASE:
      return "RELEASE_LEASE";
  }
  return "command " + std::to_string(static_cast<std::uint32_t>(command));
}

std::string_view result_code_name(msg::ResultCode code) {
  switch (code) {
    case msg::OK:
      return "OK";
    case msg::INVALID_ARGUMENT:
      return "INVALID_ARGUMENT";
    case msg::UNKNOWN_HAND:
      return "UNKNOWN_HAND";
    case msg::TIMEOUT:
      return "TIMEOUT";
    case msg::BUS_DOWN:
      return "BUS_DOWN";
    case msg::BUSY:
      return "BUSY";
    case msg::NOT_INITIALIZED:
      return "NOT_INITIALIZED";
    case msg::DENIED:
      return "DENIED";
    case msg::CANCELLED:
      return "CANCELLED";
    case msg::FAILED:
      return "FAILED";
  }
  return "UNKNOWN_RESULT";
}

}  // namespace dh3::contract
