#pragma once
// What the client knows of every hand: its newest status, and which service
// incarnation sent it.
//
// Not thread-safe: ClientCore keeps it under its state mutex, because a service's
// loss changes its hands' statuses and ends its calls in one step. Knows no DDS.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dh3/address.hpp"
#include "dh3/types.hpp"

namespace dh3::detail {

class StatusCache {
 public:
  /// Takes a status from `incarnation` (the status topic or a command's
  /// reply). A hand's status comes twice, in the reply to a command (the
  /// service's sample before it is written) and on the status topic, in either
  /// order: a sample from the incarnation that sent the cached one replaces it
  /// only with a higher update_seq, so each sample is cached (and posted) once,
  /// in order, and an older one never rolls the cache back. update_seq restarts
  /// with the service: a sample of another incarnation always replaces the
  /// cached one. False if `status` was not news.
  bool take(const std::string& incarnation, const HandStatus& status);

  /// Marks `service`'s online hands offline and lost; returns them as changed.
  std::vector<HandStatus> mark_lost(const std::string& service);
  /// Marks the hands of `incarnation` lost with it online again (it asserts
  /// again after a lapse, and its statuses are the newest); returns them.
  std::vector<HandStatus> mark_regained(const std::string& incarnation);

  [[nodiscard]] std::optional<HandStatus> find(const HandAddress& address) const;
  [[nodiscard]] bool has(const HandAddress& address) const;
  [[nodiscard]] bool has_service(const std::string& service) const;
  [[nodiscard]] std::vector<HandStatus> all() const;
  [[nodiscard]] std::vector<HandStatus> of_service(const std::string& service) const;
  /// The cached statuses of `only` (every hand if empty), in address order.
  [[nodiscard]] std::vector<HandStatus> matching(const std::optional<HandAddress>& only) const;
  /// Every hand with a status, then those the services' infos list without one.
  [[nodiscard]] std::vector<KnownHand> known_hands(const std::vector<ServiceInfo>& infos) const;

 private:
  std::map<HandAddress, HandStatus> statuses_;
  std::map<HandAddress, std::string> origins_;  ///< the incarnation of each cached status
};

}  // namespace dh3::detail
