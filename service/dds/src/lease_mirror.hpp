#pragma once
// A standby's copy of the leases the services of its cell granted, as their
// lease samples (dh3/hand_lease) say, kept per writer participant: at the
// takeover only the samples of the owner it takes over from count, so a
// participant that writes lease samples of its own (a forger) grants no lease.
// Samples may arrive before the writer's claim on the owner topic does, so
// nothing is judged on arrival.
//
// Time left is counted from when a sample was received: no wall clock, since
// the two PCs' clocks need not agree.
//
// Not thread-safe: LeaseFollower keeps it under its mutex. Knows no DDS.

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/contract/dh3.h"
#include "lease_table.hpp"

namespace dh3::dds {

/// A lease handed over from another service: its hand by bus name.
struct HandedLease {
  std::string bus;
  std::uint8_t can_id = 0;
  std::string holder_id;  ///< the client id
  std::string holder;     ///< as shown
  Duration left{};        ///< time left when it was handed over
};

/// The lease sample for a hand of `service`'s bus `bus`: `lease`'s holder
/// and time left, or a free hand.
[[nodiscard]] msg::HandLease lease_sample(const std::string& service, const std::string& bus,
                                          std::uint8_t can_id, const std::optional<HeldLease>& lease);

class LeaseMirror {
 public:
  explicit LeaseMirror(std::string service) : service_(std::move(service)) {}

  /// A sample participant `writer` wrote, received at `now`. Samples of
  /// another cell, of impossible hands, or of writers beyond the first
  /// kMaxWriters are dropped.
  void received(const std::string& writer, const msg::HandLease& sample, TimePoint now);
  /// The leases `writer` last said were held and that have time left at
  /// `now`, with that time.
  [[nodiscard]] std::vector<HandedLease> held_by_writer(const std::string& writer,
                                                        TimePoint now) const;

  /// Writers kept: a cell's services and standbys, with room to spare.
  static constexpr std::size_t kMaxWriters = 16;

 private:
  struct Entry {
    std::string holder_id;
    std::string holder;
    TimePoint expires;
  };
  using Hands = std::map<std::pair<std::string, std::uint8_t>, Entry>;

  std::string service_;
  std::map<std::string, Hands> by_writer_;
};

}  // namespace dh3::dds
