#include "dh3/contract/cell_partition.hpp"

namespace dh3::contract {

std::optional<std::string> cell_partition(std::string_view service) {
  if (service.empty() || service.find_first_of("*?[\\") != std::string_view::npos) {
    return std::nullopt;
  }
  return "dh3.cell." + std::string(service);
}

}  // namespace dh3::contract
