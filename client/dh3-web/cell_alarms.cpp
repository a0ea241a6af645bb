#include "cell_alarms.hpp"

#include "client_json.hpp"

namespace dh3::web {
namespace {

std::uint64_t wall_now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

std::string hand_in_words(const std::string& address, const std::string& name) {
  return "hand " + address + (name.empty() ? "" : " (" + name + ")");
}

std::string service_lost_text(const std::string& service) {
  return "Service " + service + " lost: its hands take no commands; their values are the last known";
}

/// The events that need an operator, in the words of the page's log; "" for the others.
std::string event_in_words(const HandEvent& e) {
  switch (e.kind) {
    case EventKind::dropped:
      return "DROPPED: the object fell from the fingers " +
             (e.position ? "at position " + std::to_string(*e.position)
                         : std::string("position not read yet (the next status says it)"));
    case EventKind::init_failed:
      return "Error: initialization failed";
    case EventKind::fault:
      return "Error: fault";
    default:
      return {};
  }
}

Json alarm_json(const Alarm& alarm) {
  return Json{{"id", alarm.id},
              {"key", alarm.key},
              {"text", alarm.text},
              {"condition", alarm.condition},
              {"active", alarm.active},
              {"acknowledged", alarm.acknowledged},
              {"since_ns", alarm.since_ns},
              {"over_ns", alarm.over_ns},
              {"acknowledged_ns", alarm.acknowledged_ns}};
}

}  // namespace

CellAlarms::CellAlarms(Client& client, std::size_t limit, std::chrono::milliseconds watch_every)
    : client_(client), watch_every_(watch_every), list_(limit) {
  status_subscription_ =
      client_.subscribe_status([this](const HandStatus& s) { watch_status(s); });
  event_subscription_ = client_.subscribe([this](const HandEvent& e) { on_event(e); });
  watcher_ = std::thread([this] { watch(); });
}

CellAlarms::~CellAlarms() {
  status_subscription_.unsubscribe();
  event_subscription_.unsubscribe();
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  watcher_.join();
}

void CellAlarms::set_listener(Listener listener) {
  std::lock_guard lock(mutex_);
  listener_ = std::move(listener);
}

void CellAlarms::update(const std::function<bool(AlarmList&, std::uint64_t)>& change) {
  std::string json;
  std::uint64_t version = 0;
  Listener listener;
  {
    std::lock_guard lock(mutex_);
    if (!change(list_, wall_now_ns())) return;
    json = json_locked();
    version = list_.version();
    listener = listener_;
  }
  if (listener) listener(version, json);
}

void CellAlarms::watch() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    watch_services();
    for (const auto& status : client_.hands()) watch_status(status);
    lock.lock();
    stop_.wait_for(lock, watch_every_, [this] { return stopping_; });
  }
}

void CellAlarms::watch_services() {
  for (const auto& info : client_.services()) {
    update([this, &info](AlarmList& list, std::uint64_t now) {
      ready_[info.name] = info.ready;
      if (info.ready) ever_ready_.insert(info.name);
      bool changed = list.holds("service:" + info.name,
                                !info.ready && ever_ready_.contains(info.name),
                                service_lost_text(info.name), now);
      for (const auto& bus : info.buses) {
        changed |= list.holds("bus:" + info.name + "/" + bus.name, info.ready && !bus.link_up,
                              "Bus " + info.name + "/" + bus.name + " down (" + bus.spec +
                                  "): its hands cannot be reached",
                              now);
      }
      return changed;
    });
  }
}

void CellAlarms::watch_status(const HandStatus& s) {
  const std::string address = s.address.to_string();
  update([&](AlarmList& list, std::uint64_t now) {
    if (s.service_lost) {
      return list.holds("service:" + s.address.service, true,
                        service_lost_text(s.address.service), now);
    }
    const auto service = ready_.find(s.address.service);
    if (service != ready_.end() && !service->second) return false;  // not known now
    return list.holds("offline:" + address, !s.online,
                      hand_in_words(address, s.name) + " OFFLINE: the hand does not answer", now);
  });
}

void CellAlarms::on_event(const HandEvent& e) {
  const std::string words = event_in_words(e);
  if (words.empty() || e.from_client) return;
  const std::string address = e.hand.to_string();
  std::string text = hand_in_words(address, e.name) + " " + words;
  if (!e.message.empty()) text += ": " + e.message;
  const std::string key =
      "event:" + address + ":" + std::to_string(e.event_seq) + ":" + std::to_string(e.timestamp_ns);
  update([&](AlarmList& list, std::uint64_t now) { return list.raise_once(key, text, now); });
}

void CellAlarms::record_failure(const std::string& hand, const std::string& command,
                                int http_status, const std::string& code,
                                const std::string& message) {
  const std::string text = "Command to hand " + hand + " failed: Error in " + command + " (HTTP " +
                           std::to_string(http_status) + " " + code + "): " + message;
  update([&](AlarmList& list, std::uint64_t now) {
    return list.raise_once("command:" + std::to_string(++failures_), text, now);
  });
}

std::optional<std::string> CellAlarms::acknowledge(std::uint64_t id) {
  std::optional<Alarm> acknowledged;
  update([&](AlarmList& list, std::uint64_t now) {
    const auto before = list.version();
    acknowledged = list.acknowledge(id, now);
    return list.version() != before;
  });
  if (!acknowledged) return std::nullopt;
  return json_text(alarm_json(*acknowledged));
}

std::string CellAlarms::alarms_json() const {
  std::lock_guard lock(mutex_);
  return json_locked();
}

std::string CellAlarms::json_locked() const {
  Json alarms = Json::array();
  for (const auto& alarm : list_.alarms()) alarms.push_back(alarm_json(alarm));
  return json_text(Json{{"type", "alarms"}, {"version", list_.version()}, {"alarms", alarms}});
}

}  // namespace dh3::web
