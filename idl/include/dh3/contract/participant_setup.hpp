#pragma once
// The one way a dh3 participant is set up from ParticipantOptions: the QoS
// (XML profile or the project's transports, then discovery servers, then DDS
// Security) and an owner of the participant and what it contains (the
// contract's seven topics, a publisher and a subscriber). Used by dh3-service,
// the client library, the test clients and the benchmarks, so they find each
// other the same way and fail with the same messages.

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dh3/base/result.hpp"
#include "dh3/contract/cell_partition.hpp"
#include "dh3/contract/discovery.hpp"
#include "dh3/contract/follow_filter.hpp"
#include "dh3/contract/participant.hpp"
#include "dh3/contract/participant_options.hpp"
#include "dh3/contract/reply_filter.hpp"
#include "dh3/contract/security.hpp"
#include "dh3/contract/type_support.hpp"

namespace dh3::contract {

/// True if the QoS carries the property, e.g. "dds.sec.auth.plugin".
[[nodiscard]] bool has_property(const eprosima::fastdds::dds::DomainParticipantQos& qos,
                                const std::string& name);

/// What setting a participant up has to say besides its outcome. Kept apart
/// from the Result so that a failure does not lose it: a warning about an
/// ignored option often explains the failure that follows.
struct SetupReport {
  std::vector<std::string> notes;     ///< worth an info line: the discovery servers used
  std::vector<std::string> warnings;  ///< worth a warning: options that are ignored
};

/// The participant's QoS from the options: the XML profile or the project's
/// transport default, then discovery servers, then DDS Security. Notes and
/// warnings go to `report`, whether or not it succeeds.
[[nodiscard]] Result<eprosima::fastdds::dds::DomainParticipantQos, std::string>
make_participant_qos(const ParticipantOptions& options, SetupReport& report);

/// A participant made from ParticipantOptions, with the contract's seven topics
/// (registered with the total type support), a publisher and a subscriber.
/// Readers and writers are the user's to make on them; everything the
/// participant contains is deleted with it. Only create() makes one, so a
/// Participant that exists is complete; its error says what failed, in words
/// a user can act on.
class Participant {
 public:
  /// Notes and warnings go to `report`, whether or not it succeeds.
  [[nodiscard]] static Result<std::unique_ptr<Participant>, std::string> create(
      const ParticipantOptions& options, SetupReport& report,
      eprosima::fastdds::dds::DomainParticipantListener* listener = nullptr,
      const eprosima::fastdds::dds::StatusMask& mask = eprosima::fastdds::dds::StatusMask::none());
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  /// DDS Security's access control is on: a reader or writer the permissions
  /// do not grant cannot be created.
  [[nodiscard]] bool access_control() const { return access_control_; }
  /// DDS Security comes from the XML profile rather than a security directory.
  [[nodiscard]] bool security_from_profile() const { return security_from_profile_; }
  /// Every transport is UDP (network_reach.hpp, receives_over_udp_only), as
  /// its QoS asked before the send gate wrapped them.
  [[nodiscard]] bool receives_over_udp_only() const { return udp_only_; }

  [[nodiscard]] eprosima::fastdds::dds::DomainParticipant& participant() { return *participant_; }
  [[nodiscard]] const Topics& topics() const { return topics_; }
  [[nodiscard]] eprosima::fastdds::dds::Publisher& publisher() { return *publisher_; }
  [[nodiscard]] eprosima::fastdds::dds::Subscriber& subscriber() { return *subscriber_; }
  /// Where a follower of `service` makes its readers: a subscriber in the
  /// cell's partition (dh3/contract/cell_partition.hpp), made on first use;
  /// subscriber() where the cell has none (a pattern-like name, access
  /// control), Fast DDS refuses it, or another cell was asked for first.
  [[nodiscard]] eprosima::fastdds::dds::Subscriber& cell_subscriber(const std::string& service);
  /// Likewise where a follower of `service` makes its request writers.
  [[nodiscard]] eprosima::fastdds::dds::Publisher& cell_publisher(const std::string& service);
  /// A service's cell partition, which its publisher and subscriber use
  /// besides the default one; nullopt if none.
  [[nodiscard]] const std::optional<std::string>& published_cell() const { return published_cell_; }
  /// What this participant's reply filters decided: on a service, its reply
  /// writer's (writer-side filtering); on a client, its reply reader's.
  [[nodiscard]] const ReplyFilterCounts& reply_filter_counts() const {
    return reply_filters_.counts();
  }
  /// What this participant's follow filters decided: on a service, its
  /// writers' (writer-side filtering); on a client, its readers'.
  [[nodiscard]] const FollowFilterCounts& follow_filter_counts() const {
    return follow_filters_.counts();
  }
  /// The client_id this participant puts in its CommandRequests.
  [[nodiscard]] std::string client_id() const;

 private:
  Participant() = default;

  /// The reply filter class, the topics, the publisher and the subscriber.
  Result<void, std::string> create_contained(const std::string& cell);

  /// The publisher or subscriber `made` in `service`'s cell partition, made
  /// with `qos` on first use; `plain` where there is none. One cell per
  /// participant: a follower follows one.
  template <typename Entity, typename Qos, typename Create>
  Entity& in_cell(const std::string& service, Entity& plain, Entity*& made, Qos qos, Create create);

  /// Outlives participant_ (members are destroyed after ~Participant's body).
  ReplyFilterFactory reply_filters_;
  FollowFilterFactory follow_filters_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  Topics topics_;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  eprosima::fastdds::dds::Subscriber* cell_subscriber_ = nullptr;
  eprosima::fastdds::dds::Publisher* cell_publisher_ = nullptr;
  std::string cell_;  ///< the partition of the two above, once one is made
  std::optional<std::string> published_cell_;
  bool security_from_profile_ = false;
  bool access_control_ = false;
  bool udp_only_ = false;
};

}  // namespace dh3::contract
