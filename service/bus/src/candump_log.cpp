#include "dh3/bus/candump_log.hpp"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <span>

#include "dh3/base/hex.hpp"

namespace dh3::bus {
namespace {

/// "(SECONDS.MICROS)" at the start of `text`; advances it past the ')'.
std::optional<WallTime> parse_time(std::string_view& text) {
  const std::size_t dot = text.find('.');
  const std::size_t close = text.find(')');
  if (text.empty() || text[0] != '(' || dot == std::string_view::npos ||
      close == std::string_view::npos || dot > close) {
    return std::nullopt;
  }
  std::int64_t seconds = 0;
  std::int64_t fraction = 0;
  const char* begin = text.data();
  if (std::from_chars(begin + 1, begin + dot, seconds).ptr != begin + dot) return std::nullopt;
  if (std::from_chars(begin + dot + 1, begin + close, fraction).ptr != begin + close) {
    return std::nullopt;
  }
  // candump writes six decimals (nine with -t ns in newer versions): scale to ns.
  std::size_t digits = close - dot - 1;
  if (digits == 0 || digits > 9) return std::nullopt;
  for (; digits < 9; ++digits) fraction *= 10;
  text.remove_prefix(close + 1);
  return WallTime(std::chrono::duration_cast<WallTime::duration>(
      std::chrono::seconds(seconds) + std::chrono::nanoseconds(fraction)));
}

std::string_view next_word(std::string_view& text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  std::size_t end = 0;
  while (end < text.size() && text[end] != ' ' && text[end] != '\t') ++end;
  const std::string_view word = text.substr(0, end);
  text.remove_prefix(end);
  return word;
}

/// "123#0102..." into `frame`.
Result<void, LogLineError> parse_frame(std::string_view text, CanFrame& frame) {
  const std::size_t hash = text.find('#');
  if (hash == std::string_view::npos) return fail(LogLineError::malformed);
  if (hash == 8 || text.find("##") == hash) return fail(LogLineError::unsupported);  // EFF, FD
  if (hash != 3) return fail(LogLineError::malformed);
  frame.id = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto digit = hex_digit(text[i]);
    if (!digit) return fail(LogLineError::malformed);
    frame.id = (frame.id << 4U) | *digit;
  }
  if (frame.id > 0x7FF) return fail(LogLineError::malformed);
  std::string_view data = text.substr(hash + 1);
  if (!data.empty() && (data[0] == 'R' || data[0] == 'r')) return fail(LogLineError::unsupported);
  if (data.size() % 2 != 0 || data.size() > 2 * frame.data.size()) {
    return fail(LogLineError::malformed);
  }
  frame.length = static_cast<std::uint8_t>(data.size() / 2);
  frame.data = {};
  if (!bytes_from_hex(data, std::span(frame.data).first(frame.length))) {
    return fail(LogLineError::malformed);
  }
  return {};
}

}  // namespace

std::string_view to_string(LogLineError error) {
  switch (error) {
    case LogLineError::not_a_frame:
      return "not a frame";
    case LogLineError::malformed:
      return "malformed line";
    case LogLineError::unsupported:
      return "a frame DH-3 hands do not send (extended, remote, CAN FD or error frame)";
  }
  return "unknown";
}

std::string log_device_name(std::string_view bus) {
  std::string name(bus.empty() ? std::string_view("bus") : bus);
  for (char& c : name) {
    const bool plain = std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_' ||
                       c == '.';
    if (!plain) c = '_';
  }
  return name;
}

std::string format_log_line(const LoggedFrame& logged, std::string_view device) {
  const auto since_epoch = std::chrono::duration_cast<std::chrono::microseconds>(
      logged.time.time_since_epoch());
  const std::int64_t micros = since_epoch.count();
  std::string line = fmt::format("({:010}.{:06}) {} {:03X}#", micros / 1'000'000,
                                 micros % 1'000'000, device, logged.frame.id);
  const std::size_t length = std::min<std::size_t>(logged.frame.length, logged.frame.data.size());
  for (std::size_t i = 0; i < length; ++i) fmt::format_to(std::back_inserter(line), "{:02X}",
                                                          logged.frame.data[i]);
  line += logged.direction == FrameDirection::sent ? " T\n" : " R\n";
  return line;
}

Result<LogLine, LogLineError> parse_log_line(std::string_view text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.remove_suffix(1);
  if (text.empty() || text[0] != '(') return fail(LogLineError::not_a_frame);
  LogLine line;
  const auto time = parse_time(text);
  if (!time) return fail(LogLineError::malformed);
  line.time = *time;
  line.device = std::string(next_word(text));
  const std::string_view frame = next_word(text);
  if (line.device.empty() || frame.empty()) return fail(LogLineError::malformed);
  if (auto parsed = parse_frame(frame, line.frame); !parsed) return fail(parsed.error());
  const std::string_view extra = next_word(text);
  if (extra == "T") line.direction = FrameDirection::sent;
  if (extra == "R") line.direction = FrameDirection::received;
  return line;
}

}  // namespace dh3::bus
