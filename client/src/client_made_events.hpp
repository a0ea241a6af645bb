#pragma once
// The events a client tells itself about the hands of a service it lost:
// OFFLINE when the service left the domain without saying so (killed, frozen,
// cut off, restarted), and ONLINE, once, for each hand told OFFLINE (by the
// client or by the service) that a status then shows online again, from a new
// incarnation of the service or from one the client had lost.
//
// The service's own ONLINE events are of no help then: a restarted service
// (or a standby taking over) sends them as its hands first answer, before
// this client's event reader is matched with it (events are volatile), and a
// service that was frozen or cut off, or a warm standby, never saw its hands
// go offline at all. Within one incarnation the service's own ONLINE does
// come, and the client tells none. The service's own ONLINE for a hand, if it
// still arrives after the client told one, is a double and is not passed on.
//
// TAKEN_OVER, for each hand the client knows of a service, when another
// process than before serves the service (a standby took over, a restart):
// the client tells it as it switches to the new owner, which no event of the
// new owner could do reliably (its event writer is new, its events volatile,
// and they are believed only once the client knows it as the owner).
//
// Not thread-safe: ClientCore keeps it under its state mutex, beside the
// StatusCache whose changes it follows. Knows no DDS.

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "dh3/types.hpp"

namespace dh3::detail {

class ClientMadeEvents {
 public:
  /// The wall clock in ns since the epoch: the time of an event made now.
  [[nodiscard]] static std::uint64_t now_ns();

  /// The OFFLINE event for a hand whose service was lost (`why`), made at
  /// `made_ns`; an ONLINE is owed for the hand from now on.
  HandEvent offline(const HandStatus& status, const std::string& why, std::uint64_t made_ns);
  /// The TAKEN_OVER event for a hand whose service is now served by `by`
  /// (in words) instead of `from`, made at `made_ns`.
  static HandEvent taken_over(const HandStatus& status, const std::string& from,
                              const std::string& by, std::uint64_t made_ns);
  /// A status now cached, from the service participant `incarnation`: the
  /// ONLINE event owed for its hand if it shows the hand online, made at `made_ns`.
  std::optional<HandEvent> online(const std::string& incarnation, const HandStatus& status,
                                  std::uint64_t made_ns);
  /// An event of the service participant `incarnation`, to be passed on
  /// unless it is an ONLINE this client already told for that incarnation.
  bool passes(const std::string& incarnation, const HandEvent& event);

 private:
  /// Hands told OFFLINE and not ONLINE since, with the incarnation that told
  /// it (empty: the client did).
  std::map<HandAddress, std::string> owed_;
  /// Hands whose ONLINE the client told, by the incarnation whose status
  /// showed them online, until that incarnation's next event of the hand.
  std::map<HandAddress, std::string> told_online_;
};

}  // namespace dh3::detail
