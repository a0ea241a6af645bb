// idl/include/dh3/contract/participant_setup.hpp: the one participant setup every dh3 program
// uses. Two participants made by it find each other on the contract's topics;
// options it cannot honour are refused with a message saying which.

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "dh3/contract/participant_setup.hpp"
#include "dh3/contract/qos.hpp"
#include "support/test_domain.hpp"

namespace {

using dh3::contract::Participant;
using dh3::contract::ParticipantOptions;
using dh3::contract::SetupReport;
using dh3::contract::TopicRole;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

ParticipantOptions on_test_domain(const std::string& name) {
  ParticipantOptions options;
  options.name = name;
  options.domain = dh3::test::test_domain();
  return options;
}

/// Why Participant::create refused `options`; nullopt if it made one.
std::optional<std::string> creation_error(const ParticipantOptions& options) {
  SetupReport report;
  auto participant = Participant::create(options, report);
  if (participant.has_value()) return std::nullopt;
  return std::move(participant).error();
}

TEST(ParticipantSetup, TwoParticipantsFindEachOtherOnTheContractsTopics) {
  SetupReport report;
  auto service_made = Participant::create(on_test_domain("setup-service"), report);
  auto client_made = Participant::create(on_test_domain("setup-client"), report);
  ASSERT_TRUE(service_made.has_value()) << service_made.error();
  ASSERT_TRUE(client_made.has_value()) << client_made.error();
  Participant& service = **service_made;
  Participant& client = **client_made;
  EXPECT_EQ(client.client_id().size(), 24u);
  EXPECT_NE(client.client_id(), service.client_id());

  auto* reader = service.subscriber().create_datareader(
      service.topics().request, dh3::contract::reader_qos(TopicRole::request));
  auto* writer = client.publisher().create_datawriter(
      client.topics().request, dh3::contract::writer_qos(TopicRole::request));
  ASSERT_NE(reader, nullptr);
  ASSERT_NE(writer, nullptr);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  eprosima::fastdds::dds::SubscriptionMatchedStatus matched;
  while (reader->get_subscription_matched_status(matched) ==
             eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK &&
         matched.current_count == 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(matched.current_count, 1);
}

// The transports a participant announces: UDP alone unless shared memory is
// asked for (dh3/contract/participant.hpp: Fast DDS 2.9's shared-memory listener goes
// deaf for good after a sender exits).
std::vector<std::string> transport_kinds(const ParticipantOptions& options) {
  SetupReport report;
  const auto qos = dh3::contract::make_participant_qos(options, report);
  EXPECT_TRUE(qos.has_value()) << qos.error();
  std::vector<std::string> kinds;
  if (!qos) return kinds;
  EXPECT_FALSE(qos->transport().use_builtin_transports);
  for (const auto& transport : qos->transport().user_transports) {
    if (std::dynamic_pointer_cast<eprosima::fastdds::rtps::UDPv4TransportDescriptor>(transport)) {
      kinds.emplace_back("udp");
    } else if (std::dynamic_pointer_cast<eprosima::fastdds::rtps::SharedMemTransportDescriptor>(
                   transport)) {
      kinds.emplace_back("shm");
    } else {
      kinds.emplace_back("other");
    }
  }
  return kinds;
}

TEST(ParticipantSetup, TheDefaultTransportIsUdpAlone) {
  EXPECT_THAT(transport_kinds(on_test_domain("setup")), ElementsAre("udp"));
  ParticipantOptions udp_only = on_test_domain("setup");
  udp_only.udp_only = true;
  EXPECT_THAT(transport_kinds(udp_only), ElementsAre("udp"));
}

TEST(ParticipantSetup, SharedMemoryIsAddedOnlyWhenAskedFor) {
  ParticipantOptions options = on_test_domain("setup");
  options.shared_memory = true;
  EXPECT_THAT(transport_kinds(options), ElementsAre("udp", "shm"));
}

// The client's lapse judgement asks the kernel about UDP sockets only
// (client/src/lapse_judge.hpp): the participant says whether that is all it
// receives over, as asked before the send gate wrapped its transports.
TEST(ParticipantSetup, AParticipantSaysWhetherItReceivesOverUdpAlone) {
  const auto udp_alone = [](const ParticipantOptions& options) {
    SetupReport report;
    auto participant = Participant::create(options, report);
    EXPECT_TRUE(participant.has_value()) << participant.error();
    return participant.has_value() && (*participant)->receives_over_udp_only();
  };
  EXPECT_TRUE(udp_alone(on_test_domain("setup")));
  ParticipantOptions shared = on_test_domain("setup");
  shared.shared_memory = true;
  EXPECT_FALSE(udp_alone(shared));
  ParticipantOptions profile = on_test_domain("setup");
  profile.xml_profile_file = DH3_UDP_ONLY_PROFILE;
  profile.xml_profile = "dh3_udp_only";
  EXPECT_TRUE(udp_alone(profile));
}

TEST(ParticipantSetup, UdpOnlyAndSharedMemoryTogetherAreRefused) {
  ParticipantOptions options = on_test_domain("setup");
  options.udp_only = true;
  options.shared_memory = true;
  const auto error = creation_error(options);
  ASSERT_TRUE(error.has_value());
  EXPECT_THAT(*error, HasSubstr("udp_only and shared_memory contradict each other"));
}

TEST(ParticipantSetup, HearingServicesOnlyLeavesTheDiscoveryGroupButAnnouncesToIt) {
  ParticipantOptions options = on_test_domain("setup");
  options.is_client = true;
  SetupReport report;
  const auto qos = dh3::contract::make_participant_qos(options, report);
  ASSERT_TRUE(qos.has_value()) << qos.error();
  const auto& builtin = qos->wire_protocol().builtin;
  EXPECT_TRUE(builtin.metatrafficMulticastLocatorList.empty());
  ASSERT_EQ(builtin.metatrafficUnicastLocatorList.size(), 1u);
  ASSERT_EQ(builtin.initialPeersList.size(), 1u);
  const auto& group = *builtin.initialPeersList.begin();
  EXPECT_EQ(eprosima::fastrtps::rtps::IPLocator::toIPv4string(group), "239.255.0.1");
  EXPECT_EQ(group.port, 7400u + 250u * static_cast<std::uint32_t>(options.domain));

  // A discovery server or an XML profile decides discovery instead.
  options.discovery_servers = {"127.0.0.1:11811"};
  const auto with_server = dh3::contract::make_participant_qos(options, report);
  ASSERT_TRUE(with_server.has_value()) << with_server.error();
  EXPECT_TRUE(with_server->wire_protocol().builtin.initialPeersList.empty());
}

// A busy discovery server loses clients whose lease is Fast DDS's 20 s
// (dh3/contract/discovery.hpp says how it was seen); a service keeps the default, so
// that a killed one is still noticed as soon.
TEST(ParticipantSetup, AClientOfDiscoveryServersKeepsALongerLeaseThanAService) {
  SetupReport report;
  const auto lease_of = [&](const ParticipantOptions& options) {
    const auto qos = dh3::contract::make_participant_qos(options, report);
    EXPECT_TRUE(qos.has_value()) << qos.error();
    return qos.has_value() ? qos->wire_protocol().builtin.discovery_config.leaseDuration
                           : eprosima::fastrtps::Duration_t{};
  };
  const auto fast_dds_default = eprosima::fastdds::dds::DomainParticipantQos()
                                    .wire_protocol()
                                    .builtin.discovery_config.leaseDuration;
  ASSERT_EQ(fast_dds_default.seconds, 20);
  ASSERT_NE(dh3::contract::client_lease_with_servers, fast_dds_default);

  ParticipantOptions client = on_test_domain("lease-client");
  client.is_client = true;
  client.discovery_servers = {"127.0.0.1:11811"};
  EXPECT_EQ(lease_of(client), dh3::contract::client_lease_with_servers);

  ParticipantOptions service = on_test_domain("lease-service");
  service.discovery_servers = {"127.0.0.1:11811"};
  EXPECT_EQ(lease_of(service), fast_dds_default);

  // Simple discovery: every participant checks the others itself.
  client.discovery_servers.clear();
  EXPECT_EQ(lease_of(client), fast_dds_default);
}

/// The names of the participants a participant discovered.
class Discovered : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  void on_participant_discovery(
      eprosima::fastdds::dds::DomainParticipant*,
      eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    if (info.status != eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT) {
      return;
    }
    std::lock_guard lock(mutex_);
    names_.insert(info.info.m_participantName.to_string());
    changed_.notify_all();
  }
  bool wait_for(const std::string& name) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, std::chrono::seconds(30),
                             [&] { return names_.count(name) > 0; });
  }
  bool has(const std::string& name) {
    std::lock_guard lock(mutex_);
    return names_.count(name) > 0;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::set<std::string> names_;
};

// Two clients that hear services only both find the service and never each
// other (clients started together must not pay for each other).
TEST(ParticipantSetup, ClientsThatHearServicesOnlyFindTheServiceButNotEachOther) {
  SetupReport report;
  Discovered at_service;
  Discovered at_a;
  Discovered at_b;
  auto service = Participant::create(on_test_domain("hear-service"), report, &at_service);
  ParticipantOptions a_options = on_test_domain("hear-a");
  a_options.is_client = true;
  ParticipantOptions b_options = on_test_domain("hear-b");
  b_options.is_client = true;
  auto a = Participant::create(a_options, report, &at_a);
  auto b = Participant::create(b_options, report, &at_b);
  ASSERT_TRUE(service.has_value() && a.has_value() && b.has_value());
  EXPECT_TRUE(at_a.wait_for("hear-service"));
  EXPECT_TRUE(at_b.wait_for("hear-service"));
  EXPECT_TRUE(at_service.wait_for("hear-a"));
  EXPECT_TRUE(at_service.wait_for("hear-b"));
  // A negative needs a wait: two more announcement periods of each client,
  // every one of which the service hears on the group.
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  EXPECT_FALSE(at_a.has("hear-b"));
  EXPECT_FALSE(at_b.has("hear-a"));
}

TEST(ParticipantSetup, ADomainOutOfRangeIsRefused) {
  ParticipantOptions options;
  options.domain = 233;
  const auto error = creation_error(options);
  ASSERT_TRUE(error.has_value());
  EXPECT_THAT(*error, HasSubstr("DDS domain id 233 is out of range (0-232)"));
}

TEST(ParticipantSetup, AProfileNameNeedsItsFile) {
  ParticipantOptions options = on_test_domain("setup");
  options.xml_profile = "dh3_udp_only";
  const auto error = creation_error(options);
  ASSERT_TRUE(error.has_value());
  EXPECT_THAT(*error, HasSubstr("an XML profile name needs the XML profiles file"));
}

TEST(ParticipantSetup, AnUnreadableProfilesFileIsNamed) {
  ParticipantOptions options = on_test_domain("setup");
  options.xml_profile_file = "/nonexistent/profiles.xml";
  const auto error = creation_error(options);
  ASSERT_TRUE(error.has_value());
  EXPECT_THAT(*error, HasSubstr("'/nonexistent/profiles.xml'"));
}

TEST(ParticipantSetup, ABadDiscoveryServerIsNamed) {
  ParticipantOptions options = on_test_domain("setup");
  options.discovery_servers = {"127.0.0.1:99999"};
  const auto error = creation_error(options);
  ASSERT_TRUE(error.has_value());
  EXPECT_THAT(*error, HasSubstr("127.0.0.1:99999"));
}

TEST(ParticipantSetup, ASecurityDirectoryWithoutCredentialsIsNamed) {
  ParticipantOptions options = on_test_domain("setup");
  options.security_dir = "/nonexistent/pki";
  options.security_identity = "service";
  const auto error = creation_error(options);
  ASSERT_TRUE(error.has_value());
  EXPECT_THAT(*error, HasSubstr("/nonexistent/pki"));
  EXPECT_THAT(*error, HasSubstr("identity 'service'"));
}

TEST(ParticipantSetup, TheDiscoveryServersUsedAreNoted) {
  ParticipantOptions options = on_test_domain("setup");
  options.discovery_servers = {"127.0.0.1:11811"};
  SetupReport report;
  const auto qos = dh3::contract::make_participant_qos(options, report);
  ASSERT_TRUE(qos.has_value()) << qos.error();
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_THAT(report.notes.front(), HasSubstr("127.0.0.1:11811"));
}

// dh3-service logs the warnings before the failure: an option the profile
// overrides may be why the set-up failed, so the warning must not go with it.
TEST(ParticipantSetup, AWarningSurvivesALaterFailure) {
  ParticipantOptions options = on_test_domain("setup");
  options.xml_profile_file = DH3_UDP_ONLY_PROFILE;
  options.xml_profile = "dh3_udp_only";
  options.udp_only = true;  // ignored: the profile decides the transports
  options.discovery_servers = {"127.0.0.1:99999"};
  SetupReport report;
  const auto participant = Participant::create(options, report);
  ASSERT_FALSE(participant.has_value());
  EXPECT_THAT(participant.error(), HasSubstr("127.0.0.1:99999"));
  EXPECT_THAT(report.warnings,
              ElementsAre(HasSubstr("the XML profile decides the transports: interfaces, "
                                    "udp_only and shared_memory are ignored")));
}

}  // namespace
