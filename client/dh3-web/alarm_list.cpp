#include "alarm_list.hpp"

#include <algorithm>

namespace dh3::web {

AlarmList::AlarmList(std::size_t limit) : limit_(std::max<std::size_t>(limit, 1)) {}

Alarm* AlarmList::find_unacknowledged(const std::string& key) {
  for (auto& alarm : alarms_) {
    if (alarm.key == key && !alarm.acknowledged) return &alarm;
  }
  return nullptr;
}

bool AlarmList::holds(const std::string& key, bool condition, const std::string& text,
                      std::uint64_t now_ns) {
  Alarm* listed = find_unacknowledged(key);
  if (!condition) {
    suppressed_.erase(key);
    if (listed == nullptr || !listed->active) return false;
    listed->active = false;
    listed->over_ns = now_ns;
    changed();
    return true;
  }
  if (listed != nullptr) {
    if (listed->active && listed->text == text) return false;
    if (!listed->active) {  // back before anyone acknowledged it: the same alarm again
      listed->active = true;
      listed->over_ns = 0;
      listed->since_ns = now_ns;
    }
    listed->text = text;
    changed();
    return true;
  }
  if (suppressed_.contains(key)) return false;
  add(Alarm{0, key, text, true, true, false, now_ns, 0, 0});
  return true;
}

bool AlarmList::raise_once(const std::string& key, const std::string& text,
                           std::uint64_t now_ns) {
  if (!occurred_.insert(key).second) return false;
  occurred_order_.push_back(key);
  while (occurred_order_.size() > limit_ * 4) {
    occurred_.erase(occurred_order_.front());
    occurred_order_.pop_front();
  }
  add(Alarm{0, key, text, false, true, false, now_ns, 0, 0});
  return true;
}

void AlarmList::add(Alarm alarm) {
  alarm.id = next_id_++;
  alarms_.push_back(std::move(alarm));
  while (alarms_.size() > limit_) {
    // The oldest acknowledged, else the oldest over, else the oldest.
    auto victim = std::find_if(alarms_.begin(), alarms_.end(),
                               [](const Alarm& a) { return a.acknowledged; });
    if (victim == alarms_.end()) {
      victim = std::find_if(alarms_.begin(), alarms_.end(),
                            [](const Alarm& a) { return a.condition && !a.active; });
    }
    if (victim == alarms_.end()) victim = alarms_.begin();
    alarms_.erase(victim);
  }
  changed();
}

std::optional<Alarm> AlarmList::acknowledge(std::uint64_t id, std::uint64_t now_ns) {
  for (auto& alarm : alarms_) {
    if (alarm.id != id) continue;
    if (!alarm.acknowledged) {
      alarm.acknowledged = true;
      alarm.acknowledged_ns = now_ns;
      if (alarm.condition && alarm.active) suppressed_.insert(alarm.key);
      changed();
    }
    return alarm;
  }
  return std::nullopt;
}

std::vector<Alarm> AlarmList::alarms() const { return {alarms_.rbegin(), alarms_.rend()}; }

}  // namespace dh3::web
