#include "output.hpp"

#include <algorithm>
#include <cstdio>
#include <ctime>

namespace dh3::ctl {

std::string json_string(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(c));
          out += escaped;
        } else {
          out += c;  // UTF-8 passes through: JSON text is UTF-8
        }
    }
  }
  out += '"';
  return out;
}

void JsonObject::key(std::string_view name) {
  if (!body_.empty()) body_ += ',';
  body_ += json_string(name);
  body_ += ':';
}

JsonObject& JsonObject::add(std::string_view name, std::string_view value) {
  key(name);
  body_ += json_string(value);
  return *this;
}

JsonObject& JsonObject::add(std::string_view name, std::int64_t value) {
  key(name);
  body_ += std::to_string(value);
  return *this;
}

JsonObject& JsonObject::add(std::string_view name, std::uint64_t value) {
  key(name);
  body_ += std::to_string(value);
  return *this;
}

JsonObject& JsonObject::add(std::string_view name, bool value) {
  key(name);
  body_ += value ? "true" : "false";
  return *this;
}

JsonObject& JsonObject::add(std::string_view name, const std::vector<std::uint16_t>& values) {
  key(name);
  body_ += '[';
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) body_ += ',';
    body_ += std::to_string(values[i]);
  }
  body_ += ']';
  return *this;
}

JsonObject& JsonObject::add_raw(std::string_view name, std::string_view json) {
  key(name);
  body_ += json;
  return *this;
}

std::string to_json(const HandStatus& s) {
  JsonObject o;
  o.add("type", "status")
      .add("hand", s.address.to_string())
      .add("service", s.address.service)
      .add("bus", s.address.bus)
      .add("can_id", s.address.can_id)
      .add("name", s.name)
      .add("online", s.online)
      .add("initialized", s.initialized)
      .add("grip", to_string(s.grip))
      .add("position", s.position)
      .add("target_position", s.target_position)
      .add("closing_force", s.closing_force)
      .add("opening_force", s.opening_force)
      .add("rotation", s.rotation)
      .add("rotation_target", s.rotation_target)
      .add("rotation_state", to_string(s.rotation_state))
      .add("firmware_version", s.firmware_version)
      .add("firmware_version_text", s.firmware_version_text)
      .add("last_error", to_string(s.last_error))
      .add("last_error_message", s.last_error_message)
      .add("lease_holder", s.lease_holder)
      .add("timestamp_ns", s.timestamp_ns)
      .add("update_seq", s.update_seq)
      .add("read_at_ns", s.read_at_ns)
      .add("service_lost", s.service_lost);
  return o.str();
}

std::string to_json(const HandEvent& e) {
  JsonObject o;
  o.add("type", "event")
      .add("hand", e.hand.to_string())
      .add("name", e.name)
      .add("kind", to_string(e.kind))
      .add("position", e.position)
      .add("target", e.target)
      .add("value", e.value)
      .add("message", e.message)
      .add("timestamp_ns", e.timestamp_ns)
      .add("event_seq", e.event_seq)
      .add("from_client", e.from_client);
  return o.str();
}

std::string to_json(const ServiceInfo& info) {
  std::string buses = "[";
  for (std::size_t i = 0; i < info.buses.size(); ++i) {
    const auto& bus = info.buses[i];
    std::string hands = "[";
    for (std::size_t h = 0; h < bus.hands.size(); ++h) {
      if (h > 0) hands += ',';
      hands += JsonObject().add("can_id", bus.hands[h].can_id).add("name", bus.hands[h].name).str();
    }
    hands += ']';
    if (i > 0) buses += ',';
    buses += JsonObject()
                 .add("name", bus.name)
                 .add("spec", bus.spec)
                 .add("link_up", bus.link_up)
                 .add_raw("hands", hands)
                 .str();
  }
  buses += ']';
  JsonObject o;
  o.add("type", "service")
      .add("service", info.name)
      .add("version", info.version)
      .add("host", info.host)
      .add("admin_allowed", info.admin_allowed)
      .add("ready", info.ready)
      .add("started_ns", info.started_ns)
      .add_raw("buses", buses);
  return o.str();
}

std::string reply_json(std::string_view command, std::string_view target, const Reply& reply) {
  JsonObject o;
  o.add("type", "reply")
      .add("command", command)
      .add("hand", target)
      .add("ok", reply.ok())
      .add("code", to_string(reply.code))
      .add("message", reply.message)
      .add("value", reply.value);
  if (reply.grasp != GraspOutcome::none) o.add("grasp", to_string(reply.grasp));
  if (command == "scan") o.add("found_ids", reply.found_ids);
  if (!reply.lease_holder.empty()) o.add("lease_holder", reply.lease_holder);
  return o.str();
}

namespace {

std::string number_or_dash(std::int32_t value) {
  return value < 0 ? std::string("-") : std::to_string(value);
}

/// "14:03:07.250" (local time) of a wall-clock time in ns, "-" for 0 (never).
std::string time_of_day_or_dash(std::uint64_t ns) {
  if (ns == 0) return "-";
  const auto seconds = static_cast<std::time_t>(ns / 1'000'000'000U);
  std::tm local{};
  localtime_r(&seconds, &local);
  char text[32];
  std::snprintf(text, sizeof text, "%02d:%02d:%02d.%03u", local.tm_hour, local.tm_min, local.tm_sec,
                static_cast<unsigned>(ns / 1'000'000U % 1000U));
  return text;
}

std::string pad(std::string text, std::size_t width) {
  if (text.size() < width) text.append(width - text.size(), ' ');
  return text;
}

}  // namespace

std::string status_table(const std::vector<HandStatus>& hands) {
  struct Row {
    std::vector<std::string> cells;
  };
  const std::vector<std::string> header = {"HAND", "NAME",   "ONLINE", "INIT",
                                           "POS",  "TARGET", "GRIP",   "FORCE",
                                           "ROT",  "LEASE",  "READ",   "LAST ERROR"};
  std::vector<Row> rows;
  for (const auto& s : hands) {
    std::string error;
    if (s.last_error != Code::ok) {
      error = std::string(to_string(s.last_error));
      if (!s.last_error_message.empty()) error += ": " + s.last_error_message;
    }
    rows.push_back(Row{{s.address.to_string(), s.name.empty() ? "-" : s.name,
                        s.online ? "yes" : (s.service_lost ? "lost" : "no"),
                        s.initialized ? "yes" : "no", number_or_dash(s.position),
                        number_or_dash(s.target_position), std::string(to_string(s.grip)),
                        std::to_string(s.closing_force) + "/" + std::to_string(s.opening_force),
                        number_or_dash(s.rotation), s.lease_holder.empty() ? "-" : s.lease_holder,
                        time_of_day_or_dash(s.read_at_ns), error}});
  }
  std::vector<std::size_t> widths(header.size());
  for (std::size_t c = 0; c < header.size(); ++c) {
    widths[c] = header[c].size();
    for (const auto& row : rows) widths[c] = std::max(widths[c], row.cells[c].size());
  }
  const auto line = [&](const std::vector<std::string>& cells) {
    std::string out;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      // The last column is free text: no padding after it.
      out += c + 1 == cells.size() ? cells[c] : pad(cells[c], widths[c] + 2);
    }
    while (!out.empty() && out.back() == ' ') out.pop_back();
    return out + "\n";
  };
  std::string out = line(header);
  for (const auto& row : rows) out += line(row.cells);
  return out;
}

std::string status_line(const HandStatus& s) {
  std::string out = s.address.to_string();
  if (!s.name.empty()) out += " (" + s.name + ")";
  out += s.online ? " online" : (s.service_lost ? " offline (service lost)" : " offline");
  out += s.initialized ? " initialized" : " not-initialized";
  out += " position " + number_or_dash(s.position) + " target " +
         number_or_dash(s.target_position) + " grip " + std::string(to_string(s.grip)) + " force " +
         std::to_string(s.closing_force) + "/" + std::to_string(s.opening_force) + " rotation " +
         number_or_dash(s.rotation) + " " + std::string(to_string(s.rotation_state));
  if (!s.lease_holder.empty()) out += " leased by " + s.lease_holder;
  out += " read " + time_of_day_or_dash(s.read_at_ns);
  if (s.last_error != Code::ok) {
    out += " last error " + std::string(to_string(s.last_error));
    if (!s.last_error_message.empty()) out += ": " + s.last_error_message;
  }
  return out;
}

std::string event_line(const HandEvent& e) {
  std::string out = e.hand.to_string();
  if (!e.name.empty()) out += " (" + e.name + ")";
  // Appended, not "literal" + std::string: GCC 12 warns falsely about that at -O3
  // (-Wrestrict inside libstdc++'s string insert, GCC bugs 105329, 105651).
  out.append(" ").append(to_string(e.kind));
  out += " position " + std::to_string(e.position) + " target " + std::to_string(e.target) +
         " value " + std::to_string(e.value);
  if (!e.message.empty()) out += ": " + e.message;
  return out;
}

std::string service_line(const ServiceInfo& info) {
  std::string out = info.name;
  if (!info.host.empty()) out += " on " + info.host;
  out += " (version " + (info.version.empty() ? std::string("?") : info.version) + ", admin " +
         (info.admin_allowed ? "allowed" : "refused") + (info.ready ? "" : ", not ready") + ")";
  for (std::size_t i = 0; i < info.buses.size(); ++i) {
    const auto& bus = info.buses[i];
    out += (i == 0 ? ": " : "; ") + bus.name + " " + bus.spec + " link " +
           (bus.link_up ? "up" : "down") + ", hands";
    if (bus.hands.empty()) out += " none";
    for (const auto& hand : bus.hands) {
      // Appended, not "literal" + std::string: GCC 12 warns falsely about that at -O3
      // (-Wrestrict inside libstdc++'s string insert, GCC bugs 105329, 105651).
      out.append(" ").append(std::to_string(hand.can_id));
      if (!hand.name.empty()) out += "(" + hand.name + ")";
    }
  }
  return out;
}

}  // namespace dh3::ctl
