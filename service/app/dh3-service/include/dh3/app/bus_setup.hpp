#pragma once
// Opens the configured buses for the service: simulated hands get the
// per-hand settings of the config (objects, obstacles, timing); every other
// spec goes through bus::open_bus.

#include <string>
#include <vector>

#include "dh3/app/config.hpp"
#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"
#include "dh3/dds/service.hpp"

namespace dh3::app {

/// The IDs the simulated hands of a sim bus answer on: the spec's IDs
/// ("sim:1,2"), or for a bare "sim" the hands listed in the config (1 if none).
[[nodiscard]] std::vector<std::uint8_t> simulated_ids(const BusSettings& bus);

/// The hands the scheduler expects: the listed ones, a sim bus's simulated
/// hands, or none (discover them) for real buses without a list.
[[nodiscard]] std::vector<hand::HandConfig> expected_hands(const BusSettings& bus);

/// Opens every bus; fails with a message naming the bus that could not be opened.
[[nodiscard]] Result<std::vector<dds::BusSetup>, std::string> open_buses(
    const ServiceConfig& config, const Clock& clock);

}  // namespace dh3::app
