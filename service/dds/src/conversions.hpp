#pragma once
// Between the wire types (idl/dh3.idl, namespace dh3::msg) and the hand
// layer's types. Pure functions; the only DDS they know is the generated types.

#include <cstdint>
#include <string>
#include <string_view>

#include "dh3/contract/dh3.h"
#include "dh3/contract/names.hpp"
#include "dh3/hand/hand_types.hpp"

namespace dh3::dds {

[[nodiscard]] msg::ResultCode to_result_code(hand::CommandError error);
[[nodiscard]] msg::GraspOutcome to_msg(hand::GraspOutcome outcome);
[[nodiscard]] msg::GripState to_msg(hand::GripState state);
[[nodiscard]] msg::RotationState to_msg(hand::RotationState state);
[[nodiscard]] msg::EventKind to_msg(hand::EventKind kind);

using contract::command_name;
using contract::result_code_name;
/// True for the enum's values (a wire value may be anything).
[[nodiscard]] bool is_valid_command(msg::CommandType command);

/// The message of a reply that failed in the hand layer, e.g.
/// "hand 2 on bus 'bus0' did not answer MOVE in time".
[[nodiscard]] std::string describe_failure(hand::CommandError error, msg::CommandType command,
                                           std::string_view bus, std::uint8_t can_id);

/// "hand 2 on bus 'bus0'", for log lines and reply messages.
[[nodiscard]] std::string hand_text(std::string_view bus, std::uint8_t can_id);

/// Who publishes a status sample, and what the service adds to the hand's state.
struct StatusContext {
  std::string_view service;
  std::string_view bus;
  std::string_view lease_holder;
  std::uint64_t update_seq = 0;
  std::uint64_t timestamp_ns = 0;  ///< wall clock, ns since the epoch
  std::uint64_t read_at_ns = 0;    ///< the state's read_at on the same wall clock; 0: never
};

/// Fills every field of `out` (reused between samples to save allocations).
void fill_status(msg::HandStatus& out, const hand::HandState& state, const StatusContext& context);

/// Fills every field of `out` from a hand event.
void fill_event(msg::HandEvent& out, const hand::HandEvent& event, std::string_view service,
                std::string_view bus, std::string_view hand_name, std::uint64_t event_seq,
                std::uint64_t timestamp_ns);

/// Wall-clock time for samples: ns since the epoch.
[[nodiscard]] std::uint64_t wall_clock_ns();

}  // namespace dh3::dds
