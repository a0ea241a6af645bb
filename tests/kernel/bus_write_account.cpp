#include "kernel/bus_write_account.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <tuple>

namespace dh3::test {
namespace {

constexpr std::uint8_t kWrite = 0x01;  ///< the read/write byte of a write

/// (CAN ID, register, value): what tells one command's write frame.
using WriteKey = std::tuple<std::uint32_t, std::uint16_t, std::int32_t>;

std::optional<LoggedFrame> parse_line(const std::string& line) {
  // "(1700000000.123456) vcan0 001#0502010037000000"
  long long seconds = 0;
  long long micros = 0;
  char interface[32];
  char frame_text[64];
  if (std::sscanf(line.c_str(), "(%lld.%lld) %31s %63s", &seconds, &micros, interface,
                  frame_text) != 4) {
    return std::nullopt;
  }
  const std::string text(frame_text);
  const auto hash = text.find('#');
  if (hash == std::string::npos || hash + 1 >= text.size() || text[hash + 1] == 'R') {
    return std::nullopt;  // not a data frame
  }
  LoggedFrame frame;
  frame.at =
      WallClock::time_point(std::chrono::seconds(seconds) + std::chrono::microseconds(micros));
  frame.can_id = static_cast<std::uint32_t>(std::stoul(text.substr(0, hash), nullptr, 16));
  for (std::size_t i = hash + 1; i + 1 < text.size(); i += 2) {
    frame.data.push_back(static_cast<std::uint8_t>(std::stoul(text.substr(i, 2), nullptr, 16)));
  }
  frame.line = line;
  return frame;
}

std::optional<WriteKey> write_key(const LoggedFrame& frame) {
  if (frame.data.size() != 8 || frame.data[2] != kWrite) return std::nullopt;
  const auto register_code = static_cast<std::uint16_t>(frame.data[0] << 8 | frame.data[1]);
  const auto value = static_cast<std::int32_t>(static_cast<std::uint32_t>(frame.data[4]) |
                                               static_cast<std::uint32_t>(frame.data[5]) << 8 |
                                               static_cast<std::uint32_t>(frame.data[6]) << 16 |
                                               static_cast<std::uint32_t>(frame.data[7]) << 24);
  return WriteKey{frame.can_id, register_code, value};
}

}  // namespace

CandumpLog read_candump_log(const std::string& path) {
  CandumpLog log;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    // "DROPCOUNT: dropped 3 CAN frames on 'vcan0' socket (total drops 3)"
    unsigned dropped = 0;
    if (std::sscanf(line.c_str(), "DROPCOUNT: dropped %u", &dropped) == 1) {
      log.dropped += dropped;
    } else if (auto frame = parse_line(line)) {
      log.frames.push_back(std::move(*frame));
    }
  }
  return log;
}

BusWriteAccount account_writes(const std::vector<LoggedCommand>& commands,
                               const std::vector<LoggedFrame>& frames) {
  BusWriteAccount account;
  account.sends.assign(commands.size(), 0);
  account.sent_after_answer.assign(commands.size(), false);
  if (commands.empty()) return account;
  // Per key, the commands with it in the order they were sent.
  std::map<WriteKey, std::vector<std::size_t>> by_key;
  for (std::size_t i = 0; i < commands.size(); ++i) {
    const auto& command = commands[i];
    by_key[{command.can_id, command.register_code, command.value}].push_back(i);
  }
  const auto first_sent = commands.front().sent;
  account.frames_of.assign(commands.size(), {});
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const auto& frame = frames[f];
    if (frame.at < first_sent) continue;
    ++account.frames;
    const auto key = write_key(frame);
    if (!key) continue;
    const auto found = by_key.find(*key);
    std::optional<std::size_t> owner;
    if (found != by_key.end()) {
      for (const std::size_t i : found->second) {
        if (commands[i].sent <= frame.at) owner = i;
      }
    }
    if (!owner) {
      account.unasked.push_back(frame);
      continue;
    }
    account.frames_of[*owner].push_back(f);
    const auto& answers = commands[*owner].answers;
    if (!answers.empty() && frame.at > answers.front().at) {
      account.sent_after_answer[*owner] = true;
    }
  }
  // Request and echo: a write sent n times shows as 2n frames (2n - 1 when
  // the last one was not echoed).
  for (std::size_t i = 0; i < commands.size(); ++i)
    account.sends[i] = (account.frames_of[i].size() + 1) / 2;
  return account;
}

}  // namespace dh3::test
