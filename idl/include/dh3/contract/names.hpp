#pragma once
// Names of the contract's enums as every participant prints them, so the
// service's messages and the client's read alike.

#include <string>
#include <string_view>

#include "dh3/contract/dh3.h"

namespace dh3::contract {

/// "MOVE", "SET_CLOSING_FORCE", ...; "command N" for a value outside the enum.
std::string command_name(msg::CommandType command);

/// "OK", "INVALID_ARGUMENT", ...; "UNKNOWN_RESULT" for a value outside the enum.
std::string_view result_code_name(msg::ResultCode code);

}  // namespace dh3::contract
