#include "round_robin.hpp"

#include <map>

namespace dh3::dds {

std::vector<std::size_t> round_robin_order(const std::vector<std::string>& callers) {
  // Each caller's requests, the callers in the order they first came.
  std::vector<std::vector<std::size_t>> queues;
  std::map<std::string, std::size_t> queue_of;
  for (std::size_t i = 0; i < callers.size(); ++i) {
    const auto [it, added] = queue_of.try_emplace(callers[i], queues.size());
    if (added) queues.emplace_back();
    queues[it->second].push_back(i);
  }
  std::vector<std::size_t> order;
  order.reserve(callers.size());
  for (std::size_t round = 0; order.size() < callers.size(); ++round) {
    for (const auto& queue : queues) {
      if (round < queue.size()) order.push_back(queue[round]);
    }
  }
  return order;
}

}  // namespace dh3::dds
