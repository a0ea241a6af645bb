#pragma once
// Whether the services' own lists of their hands rule out a hand a user named,
// so a call for it can be refused at once instead of at the end of its wait.
//
// Pure: told the services' published infos, knows no DDS and no time.

#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/address.hpp"
#include "dh3/types.hpp"

namespace dh3::detail {

/// A message saying why `spec` names no hand, if every service it could mean
/// has published its hands and none fits; nullopt while it may still appear:
/// no service it could mean is known yet, the named service's info has not
/// arrived, or a bus it could be on discovers its hands rather than listing
/// them.
[[nodiscard]] std::optional<std::string> hand_ruled_out(const HandSpec& spec,
                                                        const std::vector<ServiceInfo>& infos);

/// Why a wait found the hand's service but no status of `hand`:
/// "service 'S' has no hand BUS/ID (no status for it within T)".
[[nodiscard]] std::string no_status_for(const HandAddress& hand, std::chrono::milliseconds waited);

/// Why a wait found no service: "no service 'NAME' found on DDS domain D
/// within T", or "no dh3 service ..." for an empty `name`; then "; " and
/// `seen` if that is not empty (what discovery showed of it).
[[nodiscard]] std::string no_service_found(std::string_view name, int domain,
                                           std::chrono::milliseconds waited,
                                           const std::string& seen = {});

}  // namespace dh3::detail
