#pragma once
// What dh3ctl prints for people: compact text (its --json lines are
// client_json.hpp's). Pure formatting, tested without a service.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/client.hpp"

namespace dh3::ctl {

/// The compact table of `status` and `list`: a header and one line per hand.
[[nodiscard]] std::string status_table(const std::vector<HandStatus>& hands);
/// "cell/bus0/1 (left) online initialized position 60 target 60 grip ARRIVED ..."
[[nodiscard]] std::string status_line(const HandStatus& status);
/// "cell/bus0/1 (left) GRASPED position 42 target 0 value 40: message"
[[nodiscard]] std::string event_line(const HandEvent& event);
/// "cell on host (version 0.1.0, admin refused): bus0 sim:1,2,3 link up, hands 1 2 3"
[[nodiscard]] std::string service_line(const ServiceInfo& info);

}  // namespace dh3::ctl
