// idl/include/dh3/contract/network_reach.hpp: which transports other machines
// can reach, and the warning a service reachable from them without DDS
// Security gives at start.

#include <fastdds/rtps/transport/TCPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/UDPv6TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "dh3/contract/network_reach.hpp"
#include "dh3/contract/participant_setup.hpp"

namespace {

namespace rtps = eprosima::fastdds::rtps;
using dh3::contract::reaches_other_hosts;
using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

eprosima::fastdds::dds::DomainParticipantQos with_transports(
    std::vector<std::shared_ptr<rtps::TransportDescriptorInterface>> transports) {
  eprosima::fastdds::dds::DomainParticipantQos qos;
  qos.transport().use_builtin_transports = false;
  qos.transport().user_transports = std::move(transports);
  return qos;
}

std::shared_ptr<rtps::UDPv4TransportDescriptor> udp(std::vector<std::string> whitelist) {
  auto descriptor = std::make_shared<rtps::UDPv4TransportDescriptor>();
  descriptor->interfaceWhiteList = std::move(whitelist);
  return descriptor;
}

TEST(NetworkReach, TheProjectsDefaultStaysOnThisMachine) {
  EXPECT_FALSE(reaches_other_hosts(dh3::contract::participant_qos("reach", {})));
  EXPECT_FALSE(reaches_other_hosts(
      dh3::contract::participant_qos("reach", {.interfaces = {}, .shared_memory = true})));
}

TEST(NetworkReach, AnInterfaceBeyondLoopbackOrEveryInterfaceIsReachable) {
  EXPECT_TRUE(reaches_other_hosts(dh3::contract::participant_qos("reach", {.interfaces = {"*"}})));
  EXPECT_TRUE(reaches_other_hosts(
      dh3::contract::participant_qos("reach", {.interfaces = {"127.0.0.1", "169.254.10.1"}})));
  EXPECT_FALSE(
      reaches_other_hosts(dh3::contract::participant_qos("reach", {.interfaces = {"127.0.0.1"}})));
}

TEST(NetworkReach, FastDdsBuiltinTransportsListenOnEveryInterface) {
  eprosima::fastdds::dds::DomainParticipantQos qos;  // an XML profile that names no transport
  ASSERT_TRUE(qos.transport().use_builtin_transports);
  EXPECT_TRUE(reaches_other_hosts(qos));
}

TEST(NetworkReach, EachTransportOfAProfileCounts) {
  EXPECT_FALSE(reaches_other_hosts(with_transports({udp({"127.0.0.1"}), udp({"::1"})})));
  EXPECT_FALSE(reaches_other_hosts(
      with_transports({std::make_shared<rtps::SharedMemTransportDescriptor>()})));
  EXPECT_TRUE(reaches_other_hosts(
      with_transports({udp({"127.0.0.1"}), std::make_shared<rtps::UDPv6TransportDescriptor>()})));
  auto tcp = std::make_shared<rtps::TCPv4TransportDescriptor>();
  EXPECT_TRUE(reaches_other_hosts(with_transports({tcp})));
  tcp->interfaceWhiteList = {"127.0.0.1"};
  EXPECT_FALSE(reaches_other_hosts(with_transports({tcp})));
  EXPECT_TRUE(reaches_other_hosts(with_transports({udp({"0.0.0.0"})})));
}

TEST(NetworkReach, OnlyUdpTransportsLeaveQueuesTheKernelCanBeAskedAbout) {
  using dh3::contract::receives_over_udp_only;
  EXPECT_TRUE(receives_over_udp_only(dh3::contract::participant_qos("queues", {})));
  EXPECT_FALSE(receives_over_udp_only(
      dh3::contract::participant_qos("queues", {.interfaces = {}, .shared_memory = true})));
  EXPECT_TRUE(receives_over_udp_only(
      with_transports({udp({}), std::make_shared<rtps::UDPv6TransportDescriptor>()})));
  EXPECT_FALSE(receives_over_udp_only(eprosima::fastdds::dds::DomainParticipantQos{}))
      << "Fast DDS's built-in transports include shared memory";
  EXPECT_FALSE(receives_over_udp_only(
      with_transports({udp({}), std::make_shared<rtps::TCPv4TransportDescriptor>()})));
  EXPECT_FALSE(receives_over_udp_only(with_transports({})));
}

/// The warnings make_participant_qos reports for `options`.
std::vector<std::string> setup_warnings(const dh3::contract::ParticipantOptions& options) {
  dh3::contract::SetupReport report;
  const auto qos = dh3::contract::make_participant_qos(options, report);
  EXPECT_TRUE(qos.has_value()) << qos.error();
  return report.warnings;
}

TEST(NetworkReach, AServiceOnANetworkWithoutSecuritySaysWhatAnyoneThereCanDo) {
  dh3::contract::ParticipantOptions service;
  service.interfaces = {"*"};
  EXPECT_THAT(setup_warnings(service),
              ElementsAre(AllOf(HasSubstr("DDS Security is off"),
                                HasSubstr("anyone on that network can drive every hand"))));
  service.interfaces = {};
  EXPECT_THAT(setup_warnings(service), IsEmpty());
  // A client drives nothing it is not allowed to: the service is what is exposed.
  dh3::contract::ParticipantOptions client;
  client.interfaces = {"*"};
  client.is_client = true;
  EXPECT_THAT(setup_warnings(client), IsEmpty());
}

}  // namespace
