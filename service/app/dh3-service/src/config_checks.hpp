#pragma once
// The rules of the configuration's values that are more than a type and a
// range, each written once: the keys' table (config_keys.cpp) applies them to
// the file's values and the command line's alike.

#include <functional>
#include <string>
#include <string_view>

#include "dh3/app/config_keys.hpp"
#include "dh3/contract/participant_options.hpp"

namespace dh3::app {

[[nodiscard]] Checked check_name(std::string_view what, std::string_view name);
[[nodiscard]] Checked check_log_level(std::string_view level);
[[nodiscard]] Checked check_spec(std::string_view spec);
[[nodiscard]] Checked check_metrics_address(std::string_view address);
[[nodiscard]] Checked check_not_empty(std::string_view what, std::string_view text);

// The participant's values, one at a time.
[[nodiscard]] Checked check_interface(std::string_view address);
[[nodiscard]] Checked check_discovery_server(std::string_view entry);
[[nodiscard]] Checked check_readable_file(std::string_view what, const std::string& path);
[[nodiscard]] Checked check_identity(std::string_view identity);

/// A participant's interfaces, discovery servers, XML profile and DDS
/// Security together; when they do not fit, the key of the culprit (its
/// path, "dds.shared_memory") and why, naming the other key by `label`.
struct Misfit {
  std::string_view key;
  std::string message;
};
[[nodiscard]] Result<void, Misfit> check_participant(
    const contract::ParticipantOptions& participant,
    const std::function<std::string(std::string_view key)>& label);

}  // namespace dh3::app
