#include "client_share.hpp"

#include <spdlog/spdlog.h>

namespace dh3::dds {

struct ClientShare::Ticket::Slot {
  Slot(ClientShare& from, std::string id) : share(from), caller_id(std::move(id)) {}
  Slot(const Slot&) = delete;
  Slot& operator=(const Slot&) = delete;
  ~Slot() { share.release(caller_id); }
  ClientShare& share;
  std::string caller_id;
};

Result<ClientShare::Ticket, std::string> ClientShare::admit(const std::string& caller_id,
                                                            const std::string& shown_as) {
  {
    std::lock_guard lock(mutex_);
    Client& client = clients_[caller_id];
    if (client.in_flight >= max_) {
      std::string message = "client '" + shown_as + "' (participant " + caller_id + ") has " +
                            std::to_string(client.in_flight) + " requests in flight; at most " +
                            std::to_string(max_) + " per client: wait for their replies";
      // Once per time over its share: a flood would log a line per request.
      if (!client.warned) spdlog::warn("{}", message);
      ++refused_;
      client.warned = true;
      return fail(std::move(message));
    }
    ++client.in_flight;
  }
  return Ticket(std::make_shared<const Ticket::Slot>(*this, caller_id));
}

std::size_t ClientShare::in_flight(const std::string& caller_id) const {
  std::lock_guard lock(mutex_);
  const auto it = clients_.find(caller_id);
  return it == clients_.end() ? 0 : it->second.in_flight;
}

std::uint64_t ClientShare::refused() const {
  std::lock_guard lock(mutex_);
  return refused_;
}

void ClientShare::release(const std::string& caller_id) {
  std::lock_guard lock(mutex_);
  const auto it = clients_.find(caller_id);
  if (it == clients_.end()) return;
  // A client with nothing in flight is forgotten: the map holds only busy ones.
  if (--it->second.in_flight == 0) clients_.erase(it);
}

}  // namespace dh3::dds
