// idl/dh3_participant_setup.hpp: the one participant setup every dh3 program
// uses. Two participants made by it find each other on the contract's topics;
// options it cannot honour are refused with a message saying which.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <string>
#include <thread>

#include "dh3_participant_setup.hpp"
#include "dh3_qos.hpp"
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

TEST(ParticipantSetup, ADomainOutOfRangeIsRefused) {
  ParticipantOptions options;
  options.domain = 233;
  SetupReport report;
  const auto participant = Participant::create(options, report);
  ASSERT_FALSE(participant.has_value());
  EXPECT_THAT(participant.error(), HasSubstr("DDS domain id 233 is out of range (0-232)"));
}

TEST(ParticipantSetup, AProfileNameNeedsItsFile) {
  ParticipantOptions options = on_test_domain("setup");
  options.xml_profile = "dh3_udp_only";
  SetupReport report;
  const auto participant = Participant::create(options, report);
  ASSERT_FALSE(participant.has_value());
  EXPECT_THAT(participant.error(), HasSubstr("an XML profile name needs the XML profiles file"));
}

TEST(ParticipantSetup, AnUnreadableProfilesFileIsNamed) {
  ParticipantOptions options = on_test_domain("setup");
  options.xml_profile_file = "/nonexistent/profiles.xml";
  SetupReport report;
  const auto participant = Participant::create(options, report);
  ASSERT_FALSE(participant.has_value());
  EXPECT_THAT(participant.error(), HasSubstr("'/nonexistent/profiles.xml'"));
}

TEST(ParticipantSetup, ABadDiscoveryServerIsNamed) {
  ParticipantOptions options = on_test_domain("setup");
  options.discovery_servers = {"127.0.0.1:99999"};
  SetupReport report;
  const auto participant = Participant::create(options, report);
  ASSERT_FALSE(participant.has_value());
  EXPECT_THAT(participant.error(), HasSubstr("127.0.0.1:99999"));
}

TEST(ParticipantSetup, ASecurityDirectoryWithoutCredentialsIsNamed) {
  ParticipantOptions options = on_test_domain("setup");
  options.security_dir = "/nonexistent/pki";
  options.security_identity = "service";
  SetupReport report;
  const auto participant = Participant::create(options, report);
  ASSERT_FALSE(participant.has_value());
  EXPECT_THAT(participant.error(), HasSubstr("/nonexistent/pki"));
  EXPECT_THAT(participant.error(), HasSubstr("identity 'service'"));
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
              ElementsAre(HasSubstr("the XML profile decides the transports: interfaces and "
                                    "udp_only are ignored")));
}

}  // namespace
