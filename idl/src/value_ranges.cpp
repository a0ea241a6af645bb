#include "dh3/contract/value_ranges.hpp"

namespace dh3::contract {

std::optional<ValueRange> value_range(msg::CommandType command) {
  switch (command) {
    case msg::MOVE:
    case msg::RELEASE:
      return ValueRange{limits::POSITION_MIN, limits::POSITION_MAX,
                        "position (percent, 100 = open)"};
    case msg::ROTATE:
      return ValueRange{limits::ROTATION_MIN, limits::ROTATION_MAX,
                        "rotation (percent of 90 degrees)"};
    case msg::SET_CLOSING_FORCE:
    case msg::SET_OPENING_FORCE:
    case msg::GRASP:
      return ValueRange{limits::FORCE_MIN, limits::FORCE_MAX, "force (percent)"};
    case msg::SET_CAN_ID:
      return ValueRange{limits::CAN_ID_MIN, limits::CAN_ID_MAX, "CAN ID"};
    case msg::SET_BAUD_RATE:
      return ValueRange{limits::BAUD_INDEX_MIN, limits::BAUD_INDEX_MAX,
                        "baud rate index (0 = 500 kbps ... 5 = 100 kbps)"};
    case msg::ACQUIRE_LEASE:
    case msg::RENEW_LEASE:
      return ValueRange{limits::LEASE_TTL_MIN_MS, limits::LEASE_TTL_MAX_MS,
                        "lease time to live (ms)"};
    default:
      return std::nullopt;
  }
}

Result<void, std::string> check_value_range(const msg::CommandRequest& request) {
  const auto range = value_range(request.command());
  if (!range || (request.value() >= range->min && request.value() <= range->max)) return {};
  return dh3::fail(command_name(request.command()) + " value " + std::to_string(request.value()) +
                   " is out of range for " + range->what + " (" + std::to_string(range->min) + "-" +
                   std::to_string(range->max) + ")");
}

}  // namespace dh3::contract
