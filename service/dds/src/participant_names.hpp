#pragma once
// How people see the service's clients: each participant under the name it
// announces in discovery (dh3's client library announces "<program>@<host>"),
// so that a lease holder is shown by program and host instead of an id. A name
// is the participant's own claim and grants nothing: leases are bound to the
// participant's id (lease_table.hpp). With DDS Security the certificate's
// subject, which authentication checked, is shown beside it.
//
// Thread-safe: the participant listener writes, request listeners read.

#include <fastdds/rtps/builtin/data/ParticipantProxyData.h>

#include <map>
#include <mutex>
#include <string>

namespace dh3::dds {

class ParticipantNames {
 public:
  /// Remembers how the participant of `data` is shown.
  void discovered(const eprosima::fastrtps::rtps::ParticipantProxyData& data);
  /// Remembers `shown` for the participant `id` (contract::client_id_for's form).
  void remember(const std::string& id, std::string shown);
  void forget(const std::string& id);
  /// How the participant `id` is shown; a participant never discovered (its
  /// request overtook its announcement) is shown as unknown, never by its id.
  [[nodiscard]] std::string shown_as(const std::string& id) const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::string, std::less<>> names_;  ///< under mutex_
};

/// The words a participant is shown by, from its discovery data: its announced
/// name (else "unnamed participant at <its address>"), and the subject of its
/// identity certificate when DDS Security authenticated it; control
/// characters and other bytes outside printable ASCII escaped (escaped_for_log).
[[nodiscard]] std::string shown_name(const eprosima::fastrtps::rtps::ParticipantProxyData& data);

}  // namespace dh3::dds
