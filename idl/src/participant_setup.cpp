#include "dh3/contract/participant_setup.hpp"

#include <algorithm>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <mutex>
#include <utility>

#include "dh3/contract/network_reach.hpp"
#include "dh3/contract/send_gate.hpp"

namespace dh3::contract {

bool has_property(const eprosima::fastdds::dds::DomainParticipantQos& qos,
                  const std::string& name) {
  const auto& properties = qos.properties().properties();
  return std::any_of(properties.begin(), properties.end(),
                     [&](const auto& property) { return property.name() == name; });
}

Result<eprosima::fastdds::dds::DomainParticipantQos, std::string> make_participant_qos(
    const ParticipantOptions& options, SetupReport& report) {
  using eprosima::fastrtps::types::ReturnCode_t;
  auto* factory = eprosima::fastdds::dds::DomainParticipantFactory::get_instance();
  eprosima::fastdds::dds::DomainParticipantQos qos;
  if (!options.xml_profile_file.empty()) {
    if (factory->load_XML_profiles_file(options.xml_profile_file) != ReturnCode_t::RETCODE_OK) {
      return fail("cannot load the Fast DDS XML profiles file '" + options.xml_profile_file + "'");
    }
    if (options.xml_profile.empty()) {
      qos = factory->get_default_participant_qos();
    } else if (factory->get_participant_qos_from_profile(options.xml_profile, qos) !=
               ReturnCode_t::RETCODE_OK) {
      return fail("no participant profile '" + options.xml_profile + "' in '" +
                  options.xml_profile_file + "'");
    }
    if (qos.name().to_string().empty()) qos.name(options.name);
    // The profile decides the transports; say so rather than ignore silently.
    if (!options.interfaces.empty() || options.udp_only || options.shared_memory) {
      report.warnings.emplace_back(
          "the XML profile decides the transports: interfaces, udp_only and shared_memory "
          "are ignored");
    }
  } else if (!options.xml_profile.empty()) {
    return fail("an XML profile name needs the XML profiles file that defines it");
  } else if (options.udp_only && options.shared_memory) {
    return fail("udp_only and shared_memory contradict each other: give one of them");
  } else {
    TransportOptions transport;
    transport.interfaces = options.interfaces;
    transport.shared_memory = options.shared_memory;
    qos = participant_qos(options.name, transport);
  }
  // The configured servers; without, ROS_DISCOVERY_SERVER's, unless an XML
  // profile decides how the participant discovers.
  const auto servers = options.xml_profile_file.empty()
                           ? choose_discovery_servers(options.discovery_servers)
                           : discovery_servers_from_entries(options.discovery_servers);
  if (!servers) return fail(servers.error());
  if (!use_discovery_servers(qos, *servers)) {
    return fail("cannot use the discovery servers given");
  }
  for (const auto& server : *servers) {
    report.notes.push_back("discovery server " + server.to_string());
  }
  if (options.is_client && options.xml_profile_file.empty()) {
    if (servers->empty()) {
      hear_services_only(qos, static_cast<std::uint32_t>(options.domain));
    } else {
      use_client_lease_with_servers(qos);
    }
  }
  if (!options.security_dir.empty()) {
    if (has_property(qos, "dds.sec.auth.plugin")) {
      return fail(
          "the XML profile already enables DDS Security; give either it or a security "
          "directory, not both");
    }
    if (options.security_identity.empty()) {
      return fail("DDS Security: no identity given for the security directory");
    }
    const auto files = security_files_in(options.security_dir, options.security_identity);
    if (auto readable = check_security_files(files); !readable) {
      return fail(readable.error() + " (identity '" + options.security_identity + "' in '" +
                  options.security_dir + "')");
    }
    enable_security(qos, files);
  }
  if (!options.is_client && !has_property(qos, "dds.sec.auth.plugin") && reaches_other_hosts(qos)) {
    report.warnings.emplace_back(
        "DDS Security is off and this service is reachable from other machines: anyone on "
        "that network can drive every hand (move, grip, take free leases, stop, and change "
        "CAN IDs and baud rates where allow_admin is on) and read every status. Give "
        "dds.security, or keep dds.interfaces on loopback (docs/security.md)");
  }
  return qos;
}

Result<std::unique_ptr<Participant>, std::string> Participant::create(
    const ParticipantOptions& options, SetupReport& report,
    eprosima::fastdds::dds::DomainParticipantListener* listener,
    const eprosima::fastdds::dds::StatusMask& mask) {
  namespace fdds = eprosima::fastdds::dds;
  if (options.domain < 0 || options.domain > 232) {
    return fail("DDS domain id " + std::to_string(options.domain) + " is out of range (0-232)");
  }
  // One participant set up at a time per process: Fast DDS 2.9 reads the
  // user name with getpwuid() (SystemInfo::get_username), whose result is a
  // static buffer, so two threads setting participants up at once race
  // (ThreadSanitizer, 32 dh3::Clients started together in one process).
  static std::mutex setting_up;
  std::lock_guard setup_lock(setting_up);
  auto qos = make_participant_qos(options, report);
  if (!qos) return fail(std::move(qos).error());
  // Owns what is made from here on: a failure below deletes it.
  std::unique_ptr<Participant> made(new Participant());
  made->security_from_profile_ = has_property(*qos, "dds.sec.auth.plugin");
  made->access_control_ = has_property(*qos, "dds.sec.access.plugin");
  made->udp_only_ = contract::receives_over_udp_only(*qos);
  // Its first announcement leaves once it hears: an answer sent before would be
  // lost, and the service would not answer again (dh3/contract/send_gate.hpp).
  const auto gate = SendGate::put_before_transports(*qos);
  made->participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(
      static_cast<fdds::DomainId_t>(options.domain), *qos, listener, mask);
  if (made->participant_ != nullptr) gate->open();
  if (made->participant_ == nullptr) {
    std::string error =
        "cannot create a DDS participant on domain " + std::to_string(options.domain);
    if (!options.security_dir.empty()) {
      error += ": DDS Security did not accept the credentials of identity '" +
               options.security_identity + "' in '" + options.security_dir +
               "' (certificate, key and permissions must belong together, be signed by its "
               "CAs and be valid now)";
    } else if (made->security_from_profile_) {
      error += " (check the DDS Security credentials the XML profile names)";
    } else {
      error += " (check the domain id, the interface addresses and the XML profile)";
    }
    return fail(std::move(error));
  }
  if (auto contained = made->create_contained(options.cell); !contained) {
    return fail(contained.error());
  }
  return made;
}

Participant::~Participant() {
  if (participant_ == nullptr) return;
  // No callback may reach a listener that is being destroyed with its owner.
  participant_->set_listener(nullptr);
  participant_->delete_contained_entities();
  eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->delete_participant(
      participant_);
}

template <typename Entity, typename Qos, typename Create>
Entity& Participant::in_cell(const std::string& service, Entity& plain, Entity*& made, Qos qos,
                             Create create) {
  const auto partition = cell_partition(service);
  if (!partition || access_control_) return plain;
  if (made == nullptr && (cell_.empty() || cell_ == *partition)) {
    qos.partition().push_back(partition->c_str());
    made = create(qos);
    cell_ = *partition;
  }
  return made != nullptr && cell_ == *partition ? *made : plain;
}

eprosima::fastdds::dds::Subscriber& Participant::cell_subscriber(const std::string& service) {
  return in_cell(service, *subscriber_, cell_subscriber_,
                 eprosima::fastdds::dds::SUBSCRIBER_QOS_DEFAULT,
                 [this](const auto& qos) { return participant_->create_subscriber(qos); });
}

eprosima::fastdds::dds::Publisher& Participant::cell_publisher(const std::string& service) {
  return in_cell(service, *publisher_, cell_publisher_,
                 eprosima::fastdds::dds::PUBLISHER_QOS_DEFAULT,
                 [this](const auto& qos) { return participant_->create_publisher(qos); });
}

std::string Participant::client_id() const {
  return client_id_for(participant_->guid().guidPrefix);
}

Result<void, std::string> Participant::create_contained(const std::string& cell) {
  namespace fdds = eprosima::fastdds::dds;
  // Before any reader is discovered: a service's reply writer looks the
  // class up when a client's filtered reply reader matches it.
  if (participant_->register_content_filter_factory(kReplyFilterClass, &reply_filters_) !=
      eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
    return fail("cannot register the reply content filter");
  }
  // Likewise the follow filter, for the status, event and info writers.
  if (participant_->register_content_filter_factory(kFollowFilterClass, &follow_filters_) !=
      eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
    return fail("cannot register the follow content filter");
  }
  topics_ = create_topics(*participant_);
  const std::pair<fdds::Topic*, const std::string&> topics[] = {
      {topics_.status, dh3::topics::HAND_STATUS},
      {topics_.event, dh3::topics::HAND_EVENT},
      {topics_.info, dh3::topics::SERVICE_INFO},
      {topics_.request, dh3::topics::COMMAND_REQUEST},
      {topics_.reply, dh3::topics::COMMAND_REPLY},
      {topics_.group_request, dh3::topics::GROUP_REQUEST},
      {topics_.group_reply, dh3::topics::GROUP_REPLY},
      {topics_.owner, dh3::topics::SERVICE_OWNER},
      {topics_.admin_request, dh3::topics::ADMIN_REQUEST}};
  for (const auto& [topic, name] : topics) {
    if (topic == nullptr) return fail("cannot create the topic " + name);
  }
  fdds::PublisherQos publisher_qos = fdds::PUBLISHER_QOS_DEFAULT;
  fdds::SubscriberQos subscriber_qos = fdds::SUBSCRIBER_QOS_DEFAULT;
  if (const auto partition = cell_partition(cell); partition && !access_control_) {
    // The default partition first: every plain endpoint matches it.
    for (const char* name : {"", partition->c_str()}) {
      publisher_qos.partition().push_back(name);
      subscriber_qos.partition().push_back(name);
    }
    published_cell_ = partition;
  }
  publisher_ = participant_->create_publisher(publisher_qos);
  if (publisher_ == nullptr) return fail("cannot create the DDS publisher");
  subscriber_ = participant_->create_subscriber(subscriber_qos);
  if (subscriber_ == nullptr) return fail("cannot create the DDS subscriber");
  return {};
}

}  // namespace dh3::contract
