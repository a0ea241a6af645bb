#pragma once
// Names of this process as people read them in logs and on the wire.

#include <string>

namespace dh3 {

/// This host's name, empty if the system will not say.
[[nodiscard]] std::string host_name();

/// "<program>@<host>": how a participant is shown to people (a lease holder,
/// a participant list). `program` empty: this process's own program name.
/// A name already holding an '@' is taken as it is.
[[nodiscard]] std::string program_at_host(const std::string& program);

}  // namespace dh3
