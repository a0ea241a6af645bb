#pragma once
// What dh3ctl prints: one-line JSON objects for scripts (--json), and compact
// text for people. Pure formatting, tested without a service.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/client.hpp"

namespace dh3::ctl {

/// `text` as a JSON string literal, quotes included.
[[nodiscard]] std::string json_string(std::string_view text);

/// Builds one JSON object, members in the order added.
class JsonObject {
 public:
  JsonObject& add(std::string_view key, std::string_view value);
  JsonObject& add(std::string_view key, const char* value) {
    return add(key, std::string_view(value));
  }
  JsonObject& add(std::string_view key, const std::string& value) {
    return add(key, std::string_view(value));
  }
  JsonObject& add(std::string_view key, std::int64_t value);
  JsonObject& add(std::string_view key, std::uint64_t value);
  JsonObject& add(std::string_view key, std::int32_t value) {
    return add(key, static_cast<std::int64_t>(value));
  }
  JsonObject& add(std::string_view key, std::uint16_t value) {
    return add(key, static_cast<std::int64_t>(value));
  }
  JsonObject& add(std::string_view key, bool value);
  JsonObject& add(std::string_view key, const std::vector<std::uint16_t>& values);
  /// `json` must already be valid JSON (an object or array built here).
  JsonObject& add_raw(std::string_view key, std::string_view json);
  [[nodiscard]] std::string str() const { return "{" + body_ + "}"; }

 private:
  void key(std::string_view name);
  std::string body_;
};

[[nodiscard]] std::string to_json(const HandStatus& status);
[[nodiscard]] std::string to_json(const HandEvent& event);
[[nodiscard]] std::string to_json(const ServiceInfo& info);
/// {"command":"move","hand":"cell/bus0/1","ok":true,"code":"OK","message":"",...}:
/// the reply's fields that matter for `command`.
[[nodiscard]] std::string reply_json(std::string_view command, std::string_view target,
                                     const Reply& reply);

/// The compact table of `status` and `list`: a header and one line per hand.
[[nodiscard]] std::string status_table(const std::vector<HandStatus>& hands);
/// "cell/bus0/1 (left) online initialized position 60 target 60 grip ARRIVED ..."
[[nodiscard]] std::string status_line(const HandStatus& status);
/// "cell/bus0/1 (left) GRASPED position 42 target 0 value 40: message"
[[nodiscard]] std::string event_line(const HandEvent& event);
/// "cell on host (version 0.1.0, admin refused): bus0 sim:1,2,3 link up, hands 1 2 3"
[[nodiscard]] std::string service_line(const ServiceInfo& info);

}  // namespace dh3::ctl
