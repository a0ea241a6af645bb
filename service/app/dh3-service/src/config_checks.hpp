#pragma once
// The rules of the service's own configuration values that are more than a
// type and a range, each written once: the keys' table (config_keys.cpp)
// applies them to the file's values and the command line's alike. The DDS
// participant's rules are the contract's (dh3/contract/participant_checks.hpp).

#include <string>
#include <string_view>

#include "dh3/app/config_keys.hpp"

namespace dh3::app {

[[nodiscard]] Checked check_name(std::string_view what, std::string_view name);
[[nodiscard]] Checked check_log_level(std::string_view level);
[[nodiscard]] Checked check_role(std::string_view role);
[[nodiscard]] Checked check_spec(std::string_view spec);
[[nodiscard]] Checked check_metrics_address(std::string_view address);
[[nodiscard]] Checked check_not_empty(std::string_view what, std::string_view text);

}  // namespace dh3::app
