#pragma once
// The order in which the service serves a batch of requests taken from its
// one request reader: one request of each client in turn, each client's own
// in the order they came. A client that wrote a thousand requests ahead of
// another client's one has that one served second, not a thousand and first.
//
// Pure; knows no Fast DDS.

#include <cstddef>
#include <string>
#include <vector>

namespace dh3::dds {

/// `callers[i]` wrote the i-th request of the batch, in arrival order; the
/// indices of the batch in the order to serve them.
[[nodiscard]] std::vector<std::size_t> round_robin_order(const std::vector<std::string>& callers);

}  // namespace dh3::dds
