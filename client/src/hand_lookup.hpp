#pragma once
// Whether the services' own lists of their hands rule out a hand a user named,
// so a call for it can be refused at once instead of at the end of its wait.
//
// Pure: told the services' published infos, knows no DDS and no time.

#include <optional>
#include <string>
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

}  // namespace dh3::detail
