#pragma once
// The one way a dh3 participant is set up from ParticipantOptions: the QoS
// (XML profile or the project's transports, then discovery servers, then DDS
// Security) and an owner of the participant and what it contains (the
// contract's five topics, a publisher and a subscriber). Used by dh3-service,
// the client library, the test clients and the benchmarks, so they find each
// other the same way and fail with the same messages.

#include <algorithm>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <string>
#include <utility>
#include <vector>

#include "dh3_discovery.hpp"
#include "dh3_participant.hpp"
#include "dh3_participant_options.hpp"
#include "dh3_reply_filter.hpp"
#include "dh3_security.hpp"
#include "dh3_type_support.hpp"

namespace dh3::contract {

/// True if the QoS carries the property, e.g. "dds.sec.auth.plugin".
[[nodiscard]] inline bool has_property(const eprosima::fastdds::dds::DomainParticipantQos& qos,
                                       const std::string& name) {
  const auto& properties = qos.properties().properties();
  return std::any_of(properties.begin(), properties.end(),
                     [&](const auto& property) { return property.name() == name; });
}

struct ParticipantQos {
  eprosima::fastdds::dds::DomainParticipantQos qos;
  std::string error;                  ///< empty when qos is usable
  std::vector<std::string> notes;     ///< worth an info line: the discovery servers used
  std::vector<std::string> warnings;  ///< worth a warning: options that are ignored
  [[nodiscard]] bool ok() const { return error.empty(); }
};

/// The participant's QoS from the options: the XML profile or the project's
/// transport default, then discovery servers, then DDS Security.
[[nodiscard]] inline ParticipantQos make_participant_qos(const ParticipantOptions& options) {
  using eprosima::fastrtps::types::ReturnCode_t;
  auto* factory = eprosima::fastdds::dds::DomainParticipantFactory::get_instance();
  ParticipantQos out;
  auto& qos = out.qos;
  const auto failed = [&out](std::string error) {
    out.error = std::move(error);
    return out;
  };
  if (!options.xml_profile_file.empty()) {
    if (factory->load_XML_profiles_file(options.xml_profile_file) != ReturnCode_t::RETCODE_OK) {
      return failed("cannot load the Fast DDS XML profiles file '" + options.xml_profile_file +
                    "'");
    }
    if (options.xml_profile.empty()) {
      qos = factory->get_default_participant_qos();
    } else if (factory->get_participant_qos_from_profile(options.xml_profile, qos) !=
               ReturnCode_t::RETCODE_OK) {
      return failed("no participant profile '" + options.xml_profile + "' in '" +
                    options.xml_profile_file + "'");
    }
    if (qos.name().to_string().empty()) qos.name(options.name);
    // The profile decides the transports; say so rather than ignore silently.
    if (!options.interfaces.empty() || options.udp_only) {
      out.warnings.emplace_back(
          "the XML profile decides the transports: interfaces and udp_only are ignored");
    }
  } else if (!options.xml_profile.empty()) {
    return failed("an XML profile name needs the XML profiles file that defines it");
  } else {
    TransportOptions transport;
    transport.interfaces = options.interfaces;
    transport.udp_only = options.udp_only;
    qos = participant_qos(options.name, transport);
  }
  // The configured servers; without, ROS_DISCOVERY_SERVER's, unless an XML
  // profile decides how the participant discovers.
  const auto servers = options.xml_profile_file.empty()
                           ? choose_discovery_servers(options.discovery_servers)
                           : discovery_servers_from_entries(options.discovery_servers);
  if (!servers) return failed(servers.error());
  if (!use_discovery_servers(qos, *servers)) {
    return failed("cannot use the discovery servers given");
  }
  for (const auto& server : *servers) {
    out.notes.push_back("discovery server " + server.to_string());
  }
  if (!options.security_dir.empty()) {
    if (has_property(qos, "dds.sec.auth.plugin")) {
      return failed(
          "the XML profile already enables DDS Security; give either it or a security "
          "directory, not both");
    }
    if (options.security_identity.empty()) {
      return failed("DDS Security: no identity given for the security directory");
    }
    const auto files = security_files_in(options.security_dir, options.security_identity);
    if (auto readable = check_security_files(files); !readable) {
      return failed(readable.error() + " (identity '" + options.security_identity + "' in '" +
                    options.security_dir + "')");
    }
    enable_security(qos, files);
  }
  return out;
}

/// A participant made from ParticipantOptions, with the contract's five topics
/// (registered with the total type support), a publisher and a subscriber.
/// Readers and writers are the user's to make on them; everything the
/// participant contains is deleted with it. Check ok(); error() says what
/// failed, in words a user can act on.
class Participant {
 public:
  explicit Participant(
      const ParticipantOptions& options,
      eprosima::fastdds::dds::DomainParticipantListener* listener = nullptr,
      const eprosima::fastdds::dds::StatusMask& mask = eprosima::fastdds::dds::StatusMask::none()) {
    namespace fdds = eprosima::fastdds::dds;
    if (options.domain < 0 || options.domain > 232) {
      error_ = "DDS domain id " + std::to_string(options.domain) + " is out of range (0-232)";
      return;
    }
    auto qos = make_participant_qos(options);
    notes_ = std::move(qos.notes);
    warnings_ = std::move(qos.warnings);
    if (!qos.ok()) {
      error_ = std::move(qos.error);
      return;
    }
    security_from_profile_ = has_property(qos.qos, "dds.sec.auth.plugin");
    access_control_ = has_property(qos.qos, "dds.sec.access.plugin");
    participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(
        static_cast<fdds::DomainId_t>(options.domain), qos.qos, listener, mask);
    if (participant_ == nullptr) {
      error_ = "cannot create a DDS participant on domain " + std::to_string(options.domain);
      if (!options.security_dir.empty()) {
        error_ += ": DDS Security did not accept the credentials of identity '" +
                  options.security_identity + "' in '" + options.security_dir +
                  "' (certificate, key and permissions must belong together, be signed by its "
                  "CAs and be valid now)";
      } else if (security_from_profile_) {
        error_ += " (check the DDS Security credentials the XML profile names)";
      } else {
        error_ += " (check the domain id, the interface addresses and the XML profile)";
      }
      return;
    }
    // Before any reader is discovered: a service's reply writer looks the
    // class up when a client's filtered reply reader matches it.
    if (participant_->register_content_filter_factory(kReplyFilterClass, &reply_filters_) !=
        eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
      error_ = "cannot register the reply content filter";
      return;
    }
    topics_ = create_topics(*participant_);
    const std::pair<fdds::Topic*, const std::string&> topics[] = {
        {topics_.status, dh3::topics::HAND_STATUS},
        {topics_.event, dh3::topics::HAND_EVENT},
        {topics_.info, dh3::topics::SERVICE_INFO},
        {topics_.request, dh3::topics::COMMAND_REQUEST},
        {topics_.reply, dh3::topics::COMMAND_REPLY}};
    for (const auto& [topic, name] : topics) {
      if (topic == nullptr) {
        error_ = "cannot create the topic " + name;
        return;
      }
    }
    publisher_ = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    if (publisher_ == nullptr) {
      error_ = "cannot create the DDS publisher";
      return;
    }
    subscriber_ = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    if (subscriber_ == nullptr) error_ = "cannot create the DDS subscriber";
  }
  ~Participant() {
    if (participant_ == nullptr) return;
    // No callback may reach a listener that is being destroyed with its owner.
    participant_->set_listener(nullptr);
    participant_->delete_contained_entities();
    eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->delete_participant(
        participant_);
  }
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  [[nodiscard]] bool ok() const { return error_.empty(); }
  [[nodiscard]] const std::string& error() const { return error_; }
  /// Worth an info line even when all went well: the discovery servers used.
  [[nodiscard]] const std::vector<std::string>& notes() const { return notes_; }
  /// Worth a warning: options that are ignored.
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }
  /// DDS Security's access control is on: a reader or writer the permissions
  /// do not grant cannot be created.
  [[nodiscard]] bool access_control() const { return access_control_; }
  /// DDS Security comes from the XML profile rather than a security directory.
  [[nodiscard]] bool security_from_profile() const { return security_from_profile_; }

  [[nodiscard]] eprosima::fastdds::dds::DomainParticipant& participant() { return *participant_; }
  [[nodiscard]] const Topics& topics() const { return topics_; }
  [[nodiscard]] eprosima::fastdds::dds::Publisher& publisher() { return *publisher_; }
  [[nodiscard]] eprosima::fastdds::dds::Subscriber& subscriber() { return *subscriber_; }
  /// What this participant's reply filters decided: on a service, its reply
  /// writer's (writer-side filtering); on a client, its reply reader's.
  [[nodiscard]] const ReplyFilterCounts& reply_filter_counts() const {
    return reply_filters_.counts();
  }
  /// The client_id this participant puts in its CommandRequests.
  [[nodiscard]] std::string client_id() const {
    return client_id_for(participant_->guid().guidPrefix);
  }

 private:
  /// Outlives participant_ (members are destroyed after ~Participant's body).
  ReplyFilterFactory reply_filters_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  Topics topics_;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::string error_;
  std::vector<std::string> notes_;
  std::vector<std::string> warnings_;
  bool security_from_profile_ = false;
  bool access_control_ = false;
};

}  // namespace dh3::contract
