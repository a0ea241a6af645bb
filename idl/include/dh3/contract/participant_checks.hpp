#pragma once
// The rules a participant's options follow, each written once: dh3-service
// applies them to its configuration file's and command line's values, dh3ctl
// and dh3-web to their command lines' (participant_flags.hpp). A failed check
// says what is wrong with the value; the caller names the key or option.

#include <functional>
#include <string>
#include <string_view>

#include "dh3/base/result.hpp"
#include "dh3/contract/participant_options.hpp"

namespace dh3::contract {

/// Fine, or what is wrong with a value.
using Checked = Result<void, std::string>;

/// The highest DDS domain id: Fast DDS's default port mapping ends at 232.
inline constexpr int kMaxDomainId = 232;

[[nodiscard]] Checked check_domain(long long domain);
/// An IPv4 address of a network interface, or "*" for all.
[[nodiscard]] Checked check_interface(std::string_view address);
/// One discovery server entry, "HOST[:PORT]"; empty skips a server id.
[[nodiscard]] Checked check_discovery_server(std::string_view entry);
/// A file this process can read; `what` names it ("XML profiles file").
[[nodiscard]] Checked check_readable_file(std::string_view what, const std::string& path);
/// The security identity names a sub-directory: a plain name.
[[nodiscard]] Checked check_identity(std::string_view identity);

/// Options that do not fit together: the member of ParticipantOptions at
/// fault ("shared_memory") and why.
struct Misfit {
  std::string_view field;
  std::string message;
};
/// The options together: "*" alone among the interfaces, udp_only or
/// shared_memory, a profile with its file, and readable credentials when a
/// security directory is given. `label` names another member in the message
/// as the caller's user knows it (a key, an option).
[[nodiscard]] Result<void, Misfit> check_participant(
    const ParticipantOptions& options, const std::function<std::string(std::string_view field)>& label);

}  // namespace dh3::contract
