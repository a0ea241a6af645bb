#pragma once
// The range each command's value must fall in, from the contract's limits, so
// the client can refuse a bad value before sending it and the service refuses
// the same values with the same words.

#include <cstdint>
#include <optional>
#include <string>

#include "dh3/base/result.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/contract/names.hpp"

namespace dh3::contract {

struct ValueRange {
  std::int64_t min = 0;
  std::int64_t max = 0;
  const char* what = "";
};

/// nullopt when the command ignores its value.
std::optional<ValueRange> value_range(msg::CommandType command);

/// The request's value is in range or ignored; otherwise "MOVE value 150 is
/// out of range for position (...) (0-100)".
Result<void, std::string> check_value_range(const msg::CommandRequest& request);

}  // namespace dh3::contract
