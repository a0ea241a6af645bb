// check_profiles: loads a Fast DDS XML profiles file the way dh3's programs do
// and prints what each named participant profile amounts to, so a test script
// can compare it with what the file's comments promise.
//
//   check_profiles FILE PROFILE... [--create DOMAIN]
//
// For each PROFILE, lines of "KEY VALUE":
//   profile NAME
//   builtin_transports true|false
//   transport UDPv4|SHM|other [whitelist=A,B]
//   discovery SIMPLE|CLIENT|SERVER|...
//   server PREFIX ADDRESS:PORT           (discovery servers, one line each)
//   property NAME=VALUE                  (participant properties)
// With --create, also creates a participant from the profile on DOMAIN and
// tries dh3's endpoints (what DDS Security permissions decide):
//   participant created|refused
//   writer TOPIC created|refused         (every dh3 topic)
//   reader TOPIC created|refused
// Exit 0 if the file loaded and every profile was found, 1 otherwise.

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/log/StdoutErrConsumer.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "dh3/contract/dh3.h"
#include "dh3/contract/dh3PubSubTypes.h"
#include "dh3/contract/qos.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

const char* protocol_name(rtps::DiscoveryProtocol_t protocol) {
  switch (protocol) {
    case rtps::DiscoveryProtocol_t::NONE:
      return "NONE";
    case rtps::DiscoveryProtocol_t::SIMPLE:
      return "SIMPLE";
    case rtps::DiscoveryProtocol_t::EXTERNAL:
      return "EXTERNAL";
    case rtps::DiscoveryProtocol_t::CLIENT:
      return "CLIENT";
    case rtps::DiscoveryProtocol_t::SERVER:
      return "SERVER";
    case rtps::DiscoveryProtocol_t::BACKUP:
      return "BACKUP";
    case rtps::DiscoveryProtocol_t::SUPER_CLIENT:
      return "SUPER_CLIENT";
  }
  return "?";
}

void describe(const std::string& name, const fdds::DomainParticipantQos& qos) {
  std::cout << "profile " << name << "\n";
  std::cout << "builtin_transports " << (qos.transport().use_builtin_transports ? "true" : "false")
            << "\n";
  for (const auto& descriptor : qos.transport().user_transports) {
    if (auto udp = std::dynamic_pointer_cast<eprosima::fastdds::rtps::UDPv4TransportDescriptor>(
            descriptor)) {
      std::cout << "transport UDPv4";
      std::string list;
      for (const auto& address : udp->interfaceWhiteList)
        list += (list.empty() ? "" : ",") + address;
      if (!list.empty()) std::cout << " whitelist=" << list;
      std::cout << "\n";
    } else if (std::dynamic_pointer_cast<eprosima::fastdds::rtps::SharedMemTransportDescriptor>(
                   descriptor)) {
      std::cout << "transport SHM\n";
    } else {
      std::cout << "transport other\n";
    }
  }
  const auto& discovery = qos.wire_protocol().builtin.discovery_config;
  std::cout << "discovery " << protocol_name(discovery.discoveryProtocol) << "\n";
  for (const auto& server : discovery.m_DiscoveryServers) {
    for (const auto& locator : server.metatrafficUnicastLocatorList) {
      std::cout << "server " << server.guidPrefix << " " << rtps::IPLocator::ip_to_string(locator)
                << ":" << locator.port << "\n";
    }
  }
  for (const auto& property : qos.properties().properties()) {
    std::cout << "property " << property.name() << "=" << property.value() << "\n";
  }
}

// Which of dh3's writers and readers this participant may create.
void try_endpoints(fdds::DomainParticipant* participant) {
  using dh3::contract::TopicRole;
  struct Entry {
    const std::string& name;
    fdds::TopicDataType* type;
    TopicRole role;
  };
  const Entry entries[] = {
      {dh3::topics::HAND_STATUS, new dh3::msg::HandStatusPubSubType(), TopicRole::hand_status},
      {dh3::topics::HAND_EVENT, new dh3::msg::HandEventPubSubType(), TopicRole::hand_event},
      {dh3::topics::SERVICE_INFO, new dh3::msg::ServiceInfoPubSubType(), TopicRole::service_info},
      {dh3::topics::COMMAND_REQUEST, new dh3::msg::CommandRequestPubSubType(), TopicRole::request},
      {dh3::topics::COMMAND_REPLY, new dh3::msg::CommandReplyPubSubType(), TopicRole::reply},
      {dh3::topics::ADMIN_REQUEST, new dh3::msg::CommandRequestPubSubType(), TopicRole::request},
  };
  auto* publisher = participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  auto* subscriber = participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  for (const auto& entry : entries) {
    fdds::TypeSupport support(entry.type);
    support.register_type(participant);
    auto* topic =
        participant->create_topic(entry.name, support.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
    const bool writer =
        topic && publisher &&
        publisher->create_datawriter(topic, dh3::contract::writer_qos(entry.role)) != nullptr;
    const bool reader =
        topic && subscriber &&
        subscriber->create_datareader(topic, dh3::contract::reader_qos(entry.role)) != nullptr;
    std::cout << "writer " << entry.name << " " << (writer ? "created" : "refused") << "\n";
    std::cout << "reader " << entry.name << " " << (reader ? "created" : "refused") << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: check_profiles FILE PROFILE... [--create DOMAIN]\n";
    return 2;
  }
  const std::string file = argv[1];
  std::vector<std::string> profiles;
  int domain = -1;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--create" && i + 1 < argc) {
      domain = std::atoi(argv[++i]);
    } else {
      profiles.push_back(arg);
    }
  }
  // Fast DDS logs to stdout from its own thread: send it to stderr, so its
  // lines do not break into this program's report.
  fdds::Log::ClearConsumers();
  fdds::Log::RegisterConsumer(std::make_unique<fdds::StdoutErrConsumer>());
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  if (factory->load_XML_profiles_file(file) != ReturnCode_t::RETCODE_OK) {
    std::cout << "load failed " << file << "\n";
    return 1;
  }
  std::cout << "loaded " << file << "\n";
  int status = 0;
  for (const auto& name : profiles) {
    fdds::DomainParticipantQos qos;
    if (factory->get_participant_qos_from_profile(name, qos) != ReturnCode_t::RETCODE_OK) {
      std::cout << "profile " << name << " missing\n";
      status = 1;
      continue;
    }
    describe(name, qos);
    if (domain < 0) continue;
    auto* participant = factory->create_participant_with_profile(
        static_cast<fdds::DomainId_t>(domain), name, nullptr, fdds::StatusMask::none());
    std::cout << "participant " << (participant ? "created" : "refused") << "\n";
    if (participant == nullptr) continue;
    try_endpoints(participant);
    participant->delete_contained_entities();
    factory->delete_participant(participant);
  }
  std::cout << std::flush;
  return status;
}
