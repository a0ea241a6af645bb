// ClientMadeEvents: OFFLINE for the hands of a lost service, TAKEN_OVER when
// another process serves it, ONLINE once it is back.

#include "client_made_events.hpp"

#include <chrono>

namespace dh3::detail {

namespace {

HandEvent made_event(const HandStatus& status, EventKind kind, std::string message,
                     std::uint64_t made_ns) {
  HandEvent event;
  event.hand = status.address;
  event.name = status.name;
  event.kind = kind;
  if (status.position >= 0) event.position = status.position;
  event.target = status.target_position;
  event.message = std::move(message);
  event.timestamp_ns = made_ns;
  event.from_client = true;
  return event;
}

}  // namespace

std::uint64_t ClientMadeEvents::now_ns() {
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(now).count());
}

HandEvent ClientMadeEvents::offline(const HandStatus& status, const std::string& why,
                                    std::uint64_t made_ns) {
  owed_[status.address] = "";
  told_online_.erase(status.address);
  return made_event(status, EventKind::offline, why, made_ns);
}

HandEvent ClientMadeEvents::taken_over(const HandStatus& status, const std::string& from,
                                        const std::string& by, std::uint64_t made_ns) {
  return made_event(status, EventKind::taken_over,
                    "service '" + status.address.service + "' is now served by " + by +
                        ", which took over from " + from,
                    made_ns);
}

std::optional<HandEvent> ClientMadeEvents::online(const std::string& incarnation,
                                                  const HandStatus& status, std::uint64_t made_ns) {
  if (!status.online || status.service_lost) return std::nullopt;
  const auto owed = owed_.find(status.address);
  // The incarnation that told OFFLINE itself tells ONLINE: this client's
  // event reader is matched with it.
  if (owed == owed_.end() || owed->second == incarnation) return std::nullopt;
  owed_.erase(owed);
  told_online_[status.address] = incarnation;
  HandEvent event = made_event(status, EventKind::online,
                               "service '" + status.address.service + "' is back", made_ns);
  event.value = status.firmware_version;  // what the service's own ONLINE carries
  return event;
}

bool ClientMadeEvents::passes(const std::string& incarnation, const HandEvent& event) {
  if (event.kind == EventKind::offline) {
    owed_[event.hand] = incarnation;
    told_online_.erase(event.hand);
    return true;
  }
  if (event.kind == EventKind::online && owed_.erase(event.hand) > 0) return true;
  const auto told = told_online_.find(event.hand);
  if (told == told_online_.end() || told->second != incarnation) return true;
  // One service's events come in order, its ONLINE for a hand before any
  // other of that hand: after any other, none of it is still to come.
  told_online_.erase(told);
  return event.kind != EventKind::online;
}

}  // namespace dh3::detail
