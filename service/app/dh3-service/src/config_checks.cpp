#include "config_checks.hpp"

#include <algorithm>
#include <array>

#include "dh3/app/config.hpp"
#include "dh3/bus/bus_spec.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/metrics/metrics_exporter.hpp"

namespace dh3::app {
namespace {

constexpr std::size_t kMaxNameLength = limits::MAX_NAME_LENGTH;
constexpr std::array<std::string_view, 7> kLogLevels{"trace", "debug",    "info", "warn",
                                                     "error", "critical", "off"};

}  // namespace

Checked check_name(std::string_view what, std::string_view name) {
  if (name.empty()) return fail(std::string(what) + " is empty");
  if (name.size() > kMaxNameLength) {
    return fail(std::string(what) + " '" + std::string(name) + "' is longer than " +
                std::to_string(kMaxNameLength) + " characters");
  }
  return {};
}

Checked check_log_level(std::string_view level) {
  if (std::find(kLogLevels.begin(), kLogLevels.end(), level) != kLogLevels.end()) {
    return {};
  }
  return fail("log level '" + std::string(level) +
              "' is not one of trace, debug, info, warn, error, critical, off");
}

Checked check_role(std::string_view role) {
  if (role == kRoleActive || role == kRoleStandby || role == kRoleAuto) return {};
  return fail("role '" + std::string(role) + "' is not one of active, standby, auto");
}

Checked check_spec(std::string_view spec) {
  auto parsed = bus::parse_bus_spec(spec);
  if (!parsed) return fail(parsed.error());
  return {};
}

Checked check_metrics_address(std::string_view address) {
  // Empty: not served (the command line's way to turn the file's off).
  if (address.empty()) return {};
  return metrics::check_listen_address(address);
}

Checked check_not_empty(std::string_view what, std::string_view text) {
  if (text.empty()) return fail(std::string(what) + " is empty");
  return {};
}

}  // namespace dh3::app
