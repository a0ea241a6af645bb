#pragma once
// A DDS partition per cell, so that a client following one cell does not
// even match the writers of the others. With the follow filter alone
// (dh3/contract/follow_filter.hpp) every service's status, event and info writers
// still match every follower and, being reliable, send it a heartbeat for
// their history and a gap for each sample filtered out for it: bytes that
// grow with the plant (BENCHMARKS.md section 9). A service publishes in the
// default partition, where every plain reader (another vendor's included)
// finds it, and in its cell's; a follower reads in its cell's only.
//
// Not under DDS Security's access control: its permissions name the
// partitions an identity may use (the default one only, in dh3's), so there
// the follow filter alone serves followers.

#include <optional>
#include <string>
#include <string_view>

namespace dh3::contract {

/// The partition of the cell served by `service`; nullopt for a name that
/// DDS would read as a pattern ('*', '?', '[', '\\'): such a cell is served
/// by the follow filter alone.
[[nodiscard]] std::optional<std::string> cell_partition(std::string_view service);

}  // namespace dh3::contract
