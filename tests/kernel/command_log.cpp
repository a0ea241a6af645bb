#include "kernel/command_log.hpp"

#include <algorithm>

namespace dh3::test {

std::size_t CommandLog::sent(int client, std::uint16_t can_id, std::uint16_t register_code,
                             std::int32_t value) {
  std::lock_guard lock(mutex_);
  commands_.push_back({client, can_id, register_code, value, WallClock::now(), {}});
  return commands_.size() - 1;
}

void CommandLog::answer(std::size_t index, const Reply& reply) {
  const auto at = WallClock::now();
  std::lock_guard lock(mutex_);
  commands_.at(index).answers.push_back({reply.code, reply.message, at});
}

std::size_t CommandLog::answers(std::size_t index) const {
  std::lock_guard lock(mutex_);
  return commands_.at(index).answers.size();
}

bool CommandLog::each_answered_ok_since(WallClock::time_point since, int clients) const {
  std::vector<bool> answered(static_cast<std::size_t>(clients), false);
  std::lock_guard lock(mutex_);
  for (const auto& command : commands_) {
    if (command.sent <= since || command.client < 0 || command.client >= clients) continue;
    for (const auto& answer : command.answers) {
      if (answer.code == Code::ok) answered[static_cast<std::size_t>(command.client)] = true;
    }
  }
  return std::all_of(answered.begin(), answered.end(), [](bool ok) { return ok; });
}

std::vector<LoggedCommand> CommandLog::commands() const {
  std::lock_guard lock(mutex_);
  return commands_;
}

}  // namespace dh3::test
