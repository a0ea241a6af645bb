#include "output.hpp"

#include <algorithm>
#include <cstdio>
#include <ctime>

#include "dh3/registers.hpp"

namespace dh3::ctl {

namespace {

std::string number_or_dash(std::int32_t value) {
  return value < 0 ? std::string("-") : std::to_string(value);
}

/// Why a hand is offline, as far as its status tells.
std::string offline_as_text(const HandStatus& s) {
  if (s.service_lost) return "service lost";
  return s.read_at_ns == 0 ? "never answered" : "no";
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

/// The value where it says something the kind does not: GRASPED's force, ONLINE's
/// firmware, OFFLINE's unanswered requests. A grip or rotation status value only
/// repeats the kind, and a FAULT's message says what the hand answered.
std::string value_text(const HandEvent& e) {
  switch (e.kind) {
    case EventKind::grasped:
      return " force " + std::to_string(e.value);
    case EventKind::online:
      return " firmware " + firmware_version_text(e.value);
    case EventKind::offline:
      return e.value > 0 ? " after " + std::to_string(e.value) + " unanswered requests" : "";
    default:
      return "";
  }
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
                        s.online ? "yes" : (s.service_lost ? "lost" : offline_as_text(s)),
                        s.initialized ? "yes" : "no", number_or_dash(s.position),
                        number_or_dash(s.target_position), std::string(to_string(s.grip)),
                        number_or_dash(s.closing_force) + "/" + number_or_dash(s.opening_force),
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
  out += s.online ? " online" : " offline (" + offline_as_text(s) + ")";
  out += s.initialized ? " initialized" : " not-initialized";
  out += " position " + number_or_dash(s.position) + " target " +
         number_or_dash(s.target_position) + " grip " + std::string(to_string(s.grip)) + " force " +
         number_or_dash(s.closing_force) + "/" + number_or_dash(s.opening_force) + " rotation " +
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
  out += " position " +
         (e.position ? std::to_string(*e.position) : std::string("- (not read yet)")) + " target " +
         number_or_dash(e.target) + value_text(e);
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
