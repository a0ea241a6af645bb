#include "dh3/sim/replay_script.hpp"

#include <algorithm>

#include "dh3/bus/candump_log.hpp"

namespace dh3::sim {

Result<ReplayScript, std::string> ReplayScript::parse(std::string_view text) {
  ReplayScript script;
  std::size_t number = 0;
  while (!text.empty()) {
    ++number;
    const std::size_t end = std::min(text.find('\n'), text.size());
    const std::string_view raw = text.substr(0, end);
    text.remove_prefix(std::min(end + 1, text.size()));
    const auto where = [&] { return "line " + std::to_string(number) + ": "; };
    auto line = bus::parse_log_line(raw);
    if (!line) {
      if (line.error() == bus::LogLineError::malformed) {
        return fail(where() + std::string(to_string(line.error())) + ": " + std::string(raw));
      }
      if (line.error() == bus::LogLineError::unsupported) ++script.skipped_;
      continue;
    }
    if (!line->direction) {
      return fail(where() + "no direction (T or R) after the frame: record with dh3-service, "
                            "or candump -L -x on the service's host");
    }
    if (script.device_.empty()) script.device_ = line->device;
    if (line->device != script.device_) {
      return fail(where() + "a second bus, '" + line->device + "' after '" + script.device_ +
                  "': replay one bus's recording");
    }
    if (line->frame.id > 0xFF || line->frame.length != protocol::kPayloadSize) {
      ++script.skipped_;
      continue;
    }
    const auto message =
        protocol::decode_payload(static_cast<std::uint8_t>(line->frame.id), line->frame.data);
    if (!message) {
      ++script.skipped_;
      continue;
    }
    if (!script.first_time_) script.first_time_ = line->time;
    ++script.frames_;
    if (*line->direction == bus::FrameDirection::sent) {
      script.add_request(*message, line->time);
    } else {
      script.add_received(*message, line->time);
    }
  }
  script.drop_silent_hands();
  return script;
}

RecordedHand& ReplayScript::hand(std::uint8_t id) {
  auto [entry, fresh] = hands_.try_emplace(id);
  if (fresh) {
    entry->second.id = id;
    entry->second.epochs.emplace_back();
    epoch_start_[id] = *first_time_;
  }
  return entry->second;
}

void ReplayScript::add_request(const protocol::Message& request, bus::WallTime time) {
  RecordedHand& target = hand(request.hand_id);
  in_flight_[request.hand_id] = InFlight{request.reg, request.access, time};
  if (request.access == protocol::Access::write) {
    target.epochs.emplace_back();
    epoch_start_[request.hand_id] = time;
  }
}

void ReplayScript::add_received(const protocol::Message& message, bus::WallTime time) {
  RecordedHand& from = hand(message.hand_id);
  answered_[message.hand_id] = true;
  const auto asked = in_flight_.find(message.hand_id);
  if (asked != in_flight_.end() && asked->second.reg == message.reg) {
    const Duration latency =
        std::max(Duration::zero(), std::chrono::duration_cast<Duration>(time - asked->second.sent));
    ReplyQueues& queues = asked->second.access == protocol::Access::write
                              ? from.writes
                              : from.epochs.back().reads;
    queues[message.reg.code()].push_back(RecordedReply{message, latency});
    in_flight_.erase(asked);
    return;
  }
  const Duration offset = std::max(
      Duration::zero(), std::chrono::duration_cast<Duration>(time - epoch_start_[message.hand_id]));
  from.epochs.back().unasked.push_back(RecordedUnasked{message, offset});
}

void ReplayScript::drop_silent_hands() {
  std::erase_if(hands_, [this](const auto& entry) { return !answered_[entry.first]; });
}

}  // namespace dh3::sim
