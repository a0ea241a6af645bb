#include "dh3/bus/bus_spec.hpp"

#include <net/if.h>

#include <algorithm>
#include <charconv>
#include <optional>
#include <utility>

#include "dh3/base/hand_ids.hpp"
#include "dh3/base/host_port.hpp"

namespace dh3::bus {
namespace {

constexpr std::string_view kExpectedAny =
    "expected sim, sim:ID,ID,..., socketcan:IFACE, tcp:HOST:PORT or serial:DEVICE@BAUD";

std::string bad(std::string_view text, std::string_view why) {
  return "bad bus spec '" + std::string(text) + "': " + std::string(why);
}

/// A whole-string unsigned decimal, or nullopt (empty, sign, junk, overflow).
template <typename T>
std::optional<T> parse_unsigned(std::string_view digits) {
  if (digits.empty() ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  T value{};
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (error != std::errc() || end != digits.data() + digits.size()) return std::nullopt;
  return value;
}

std::string rates_list() {
  std::string list;
  for (const std::uint32_t rate : supported_baud_rates()) {
    if (!list.empty()) list += ", ";
    list += std::to_string(rate);
  }
  return list;
}

Result<BusSpec, std::string> parse_sim(std::string_view text, std::string_view rest,
                                       bool has_colon) {
  BusSpec spec;
  spec.kind = BusKind::sim;
  if (!has_colon) {
    spec.sim_hand_ids = {1};  // the document's default CAN ID
    return spec;
  }
  if (rest.empty()) return dh3::fail(bad(text, "no hand ids after 'sim:' (expected sim:1,2,3)"));
  auto ids = parse_hand_ids(rest);
  if (!ids) return dh3::fail(bad(text, ids.error() + " (expected sim:1,2,3)"));
  spec.sim_hand_ids = *std::move(ids);
  return spec;
}

Result<BusSpec, std::string> parse_socketcan(std::string_view text, std::string_view rest) {
  if (rest.empty()) {
    return dh3::fail(
        bad(text, "missing interface name (expected socketcan:IFACE, e.g. socketcan:can0)"));
  }
  if (rest.size() >= IFNAMSIZ) {
    return dh3::fail(bad(text, "interface name '" + std::string(rest) + "' is longer than " +
                                   std::to_string(IFNAMSIZ - 1) + " characters"));
  }
  const bool valid_chars = std::none_of(rest.begin(), rest.end(), [](char c) {
    return c == '/' || c == ':' || c == ' ' || c == '\t' || c == '\n' || c == '\0';
  });
  if (!valid_chars || rest == "." || rest == "..") {
    // Appended, not "literal" + std::string: GCC 12 warns falsely about that at -O3
    // (-Wrestrict inside libstdc++'s string insert, GCC bugs 105329, 105651).
    return dh3::fail(
        bad(text, std::string("'").append(rest).append("' is not a valid interface name")));
  }
  BusSpec spec;
  spec.kind = BusKind::socketcan;
  spec.interface = std::string(rest);
  return spec;
}

Result<BusSpec, std::string> parse_tcp(std::string_view text, std::string_view rest) {
  constexpr std::string_view kExpected = " (expected tcp:HOST:PORT, e.g. tcp:192.168.1.20:8888)";
  auto address = parse_host_port(rest);
  if (!address) return dh3::fail(bad(text, address.error() + std::string(kExpected)));
  BusSpec spec;
  spec.kind = BusKind::tcp;
  spec.host = std::move(address->host);
  spec.port = address->port;
  return spec;
}

Result<BusSpec, std::string> parse_serial(std::string_view text, std::string_view rest) {
  BusSpec spec;
  spec.kind = BusKind::serial;
  spec.baud_rate = kDefaultSerialBaudRate;
  std::string_view device = rest;
  if (const auto at = rest.rfind('@'); at != std::string_view::npos) {
    device = rest.substr(0, at);
    const std::string_view rate_text = rest.substr(at + 1);
    const auto rate = parse_unsigned<std::uint32_t>(rate_text);
    if (!rate) {
      return dh3::fail(bad(text, "baud rate '" + std::string(rate_text) +
                                     "' is not a number (expected serial:DEVICE@BAUD, e.g. "
                                     "serial:/dev/ttyUSB0@115200)"));
    }
    if (!is_supported_baud_rate(*rate)) {
      return dh3::fail(bad(text, "unsupported baud rate " + std::to_string(*rate) +
                                     " (supported: " + rates_list() + ")"));
    }
    spec.baud_rate = *rate;
  }
  if (device.empty()) {
    return dh3::fail(bad(text,
                         "missing device path (expected serial:DEVICE@BAUD, e.g. "
                         "serial:/dev/ttyUSB0@115200)"));
  }
  spec.device = std::string(device);
  return spec;
}

}  // namespace

std::string_view to_string(BusKind kind) {
  switch (kind) {
    case BusKind::sim:
      return "sim";
    case BusKind::socketcan:
      return "socketcan";
    case BusKind::tcp:
      return "tcp";
    case BusKind::serial:
      return "serial";
  }
  return "unknown";
}

Result<BusSpec, std::string> parse_bus_spec(std::string_view text) {
  if (text.empty()) return dh3::fail("empty bus spec (" + std::string(kExpectedAny) + ")");
  const auto colon = text.find(':');
  const std::string_view scheme = text.substr(0, colon);
  const bool has_colon = colon != std::string_view::npos;
  const std::string_view rest = has_colon ? text.substr(colon + 1) : std::string_view();
  if (scheme == "sim") return parse_sim(text, rest, has_colon);
  if (!has_colon && (scheme == "socketcan" || scheme == "tcp" || scheme == "serial")) {
    // Appended, not "literal" + std::string: GCC 12 warns falsely about that at -O3
    // (-Wrestrict inside libstdc++'s string insert, GCC bugs 105329, 105651).
    return dh3::fail(bad(text, std::string("'").append(scheme).append("' needs an argument (") +
                                   std::string(kExpectedAny) + ")"));
  }
  if (scheme == "socketcan") return parse_socketcan(text, rest);
  if (scheme == "tcp") return parse_tcp(text, rest);
  if (scheme == "serial") return parse_serial(text, rest);
  return dh3::fail(bad(
      text, "unknown bus type '" + std::string(scheme) + "' (" + std::string(kExpectedAny) + ")"));
}

bool is_simulated(std::string_view text) {
  const auto spec = parse_bus_spec(text);
  return spec && spec->kind == BusKind::sim;
}

std::string to_string(const BusSpec& spec) {
  switch (spec.kind) {
    case BusKind::sim: {
      std::string text = "sim:";
      for (std::size_t i = 0; i < spec.sim_hand_ids.size(); ++i) {
        if (i > 0) text += ',';
        text += std::to_string(spec.sim_hand_ids[i]);
      }
      return text;
    }
    case BusKind::socketcan:
      return "socketcan:" + spec.interface;
    case BusKind::tcp:
      return "tcp:" + host_port_text(spec.host, spec.port);
    case BusKind::serial:
      return "serial:" + spec.device + "@" + std::to_string(spec.baud_rate);
  }
  return "unknown";
}

namespace {

Result<std::unique_ptr<Bus>, std::string> open_parsed(const BusSpec& spec, std::string text,
                                                      const Clock& clock,
                                                      const OpenBusOptions& options) {
  switch (spec.kind) {
    case BusKind::sim:
      return dh3::fail(text +
                       ": simulated hands are made by the sim layer (sim::SimBus), "
                       "not opened by the bus layer");
    case BusKind::socketcan: {
      auto opened = SocketCanBus::open(std::move(text), spec.interface, clock, options.socketcan);
      if (!opened) return dh3::fail(opened.error());
      return std::unique_ptr<Bus>(std::move(opened.value()));
    }
    case BusKind::tcp:
      return std::unique_ptr<Bus>(std::make_unique<TransferBoxBus>(
          std::move(text), std::make_unique<TcpLink>(spec.host, spec.port, options.tcp), clock,
          options.transfer_box));
    case BusKind::serial:
      if (!is_supported_baud_rate(spec.baud_rate)) {
        return dh3::fail(to_string(spec) + ": unsupported baud rate " +
                         std::to_string(spec.baud_rate) + " (supported: " + rates_list() + ")");
      }
      return std::unique_ptr<Bus>(std::make_unique<TransferBoxBus>(
          std::move(text), std::make_unique<SerialLink>(spec.device, spec.baud_rate), clock,
          options.transfer_box));
  }
  return dh3::fail(std::string("unknown bus kind"));
}

}  // namespace

Result<std::unique_ptr<Bus>, std::string> open_bus(std::string_view text, const Clock& clock,
                                                   const OpenBusOptions& options) {
  auto parsed = parse_bus_spec(text);
  if (!parsed) return dh3::fail(parsed.error());
  return open_parsed(parsed.value(), std::string(text), clock, options);
}

Result<std::unique_ptr<Bus>, std::string> open_bus(const BusSpec& spec, const Clock& clock,
                                                   const OpenBusOptions& options) {
  return open_parsed(spec, to_string(spec), clock, options);
}

}  // namespace dh3::bus
