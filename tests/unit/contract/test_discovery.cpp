// dh3/contract/discovery.hpp: which discovery servers a participant uses, and that a
// participant set up by it really finds others only through a running
// `fastdds discovery` server.

#include <arpa/inet.h>
#include <fastrtps/utils/IPLocator.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "contract_participant.hpp"
#include "dh3/contract/discovery.hpp"
#include "support/process.hpp"

namespace {

using dh3::contract::DiscoveryServer;
using dh3::contract::DiscoveryServerList;
namespace rtps = eprosima::fastrtps::rtps;

// Restores ROS_DISCOVERY_SERVER as it was, whatever the test did to it.
class ContractDiscoveryEnv : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const char* value = std::getenv("ROS_DISCOVERY_SERVER")) saved_ = value;
    ::unsetenv("ROS_DISCOVERY_SERVER");
  }
  void TearDown() override {
    if (saved_) {
      ::setenv("ROS_DISCOVERY_SERVER", saved_->c_str(), 1);
    } else {
      ::unsetenv("ROS_DISCOVERY_SERVER");
    }
  }

 private:
  std::optional<std::string> saved_;
};

TEST(ContractDiscoveryServers, PositionIsTheServerIdAndPortDefaultsTo11811) {
  const auto list = dh3::contract::parse_discovery_server_list("10.0.0.1:12000;10.0.0.2");
  ASSERT_TRUE(list.ok()) << list.error();
  ASSERT_EQ(list->size(), 2U);
  EXPECT_EQ((*list)[0], (DiscoveryServer{0, "10.0.0.1", 12000}));
  EXPECT_EQ((*list)[1], (DiscoveryServer{1, "10.0.0.2", 11811}));
}

TEST(ContractDiscoveryServers, EmptyEntriesSkipIds) {
  const auto list = dh3::contract::parse_discovery_server_list(";; 192.168.7.3:4000 ;");
  ASSERT_TRUE(list.ok()) << list.error();
  ASSERT_EQ(list->size(), 1U);
  EXPECT_EQ((*list)[0], (DiscoveryServer{2, "192.168.7.3", 4000}));

  const auto none = dh3::contract::parse_discovery_server_list("");
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty());
}

TEST(ContractDiscoveryServers, MalformedEntriesAreNamedInTheError) {
  for (const std::string bad :
       {"disco_very:11811", "-discovery:11811", "10.0.0.1:0", "10.0.0.1:65536",
        "10.0.0.1:", "10.0.0.1:http", "10.0.0.300:11811", "10.0.0.1:11811;[::1]:11811"}) {
    const auto list = dh3::contract::parse_discovery_server_list(bad);
    ASSERT_FALSE(list.ok()) << bad;
    EXPECT_NE(list.error().find("discovery server '"), std::string::npos) << list.error();
  }
  const auto port = dh3::contract::parse_discovery_server_list("10.0.0.1:99999");
  ASSERT_FALSE(port.ok());
  EXPECT_NE(port.error().find("'10.0.0.1:99999'"), std::string::npos) << port.error();
  EXPECT_NE(port.error().find("1-65535"), std::string::npos) << port.error();
}

TEST(ContractDiscoveryServers, TheErrorSaysWhatIsWrongWithTheEntry) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {":11811", "discovery server ':11811': missing host"},
      {"10.0.0.1:http", "discovery server '10.0.0.1:http': port 'http' is not a number"},
      {"[::1]:11811", "discovery server '[::1]:11811': expected IPV4[:PORT] or HOST[:PORT]"},
      {"::1:11811", "discovery server '::1:11811': an IPv6 address must be in brackets"},
  };
  for (const auto& [entry, expected] : cases) {
    const auto list = dh3::contract::parse_discovery_server_list(entry);
    ASSERT_FALSE(list.ok()) << entry;
    EXPECT_NE(list.error().find(expected), std::string::npos) << list.error();
  }
}

// As Fast DDS reads ROS_DISCOVERY_SERVER: a host name stands for its address.
TEST(ContractDiscoveryServers, AHostNameIsResolved) {
  const auto list = dh3::contract::parse_discovery_server_list("localhost:7410");
  ASSERT_TRUE(list.ok()) << list.error();
  ASSERT_EQ(list->size(), 1U);
  EXPECT_EQ((*list)[0], (DiscoveryServer{0, "127.0.0.1", 7410}));
}

TEST(ContractDiscoveryServers, AtMost256Positions) {
  std::vector<std::string> entries(256);
  entries.back() = "10.0.0.1";
  EXPECT_TRUE(dh3::contract::discovery_servers_from_entries(entries).ok());
  entries.emplace_back("10.0.0.2");
  const auto list = dh3::contract::discovery_servers_from_entries(entries);
  ASSERT_FALSE(list.ok());
  EXPECT_NE(list.error().find("ids 0-255"), std::string::npos) << list.error();
}

// The same text gives the same servers as Fast DDS's own reading of
// ROS_DISCOVERY_SERVER: a participant configured by dh3 and one configured by
// the environment variable alone point at the same servers.
TEST(ContractDiscoveryServers, AgreesWithFastDdsOwnParser) {
  for (const std::string text : {"127.0.0.1:11811", "10.1.2.3:5000;10.1.2.4:5001", "localhost",
                                 ";169.254.3.1:7400", "192.168.0.9"}) {
    const auto ours = dh3::contract::parse_discovery_server_list(text);
    ASSERT_TRUE(ours.ok()) << ours.error();
    eprosima::fastdds::dds::DomainParticipantQos qos;
    ASSERT_TRUE(dh3::contract::use_discovery_servers(qos, *ours));
    const auto& mine = qos.wire_protocol().builtin.discovery_config.m_DiscoveryServers;

    rtps::RemoteServerList_t theirs;
    ASSERT_TRUE(rtps::load_environment_server_info(text, theirs)) << text;
    ASSERT_EQ(mine.size(), theirs.size()) << text;
    auto a = mine.begin();
    for (auto b = theirs.begin(); b != theirs.end(); ++a, ++b) {
      EXPECT_EQ(a->guidPrefix, b->guidPrefix) << text;
      EXPECT_EQ(a->metatrafficUnicastLocatorList, b->metatrafficUnicastLocatorList) << text;
    }
  }
}

TEST_F(ContractDiscoveryEnv, ConfiguredServersWinOverTheEnvironment) {
  ::setenv("ROS_DISCOVERY_SERVER", "10.9.9.9:1111", 1);
  const auto configured = dh3::contract::choose_discovery_servers({"10.0.0.5:2222"});
  ASSERT_TRUE(configured.ok()) << configured.error();
  ASSERT_EQ(configured->size(), 1U);
  EXPECT_EQ((*configured)[0], (DiscoveryServer{0, "10.0.0.5", 2222}));

  const auto from_env = dh3::contract::choose_discovery_servers({});
  ASSERT_TRUE(from_env.ok()) << from_env.error();
  ASSERT_EQ(from_env->size(), 1U);
  EXPECT_EQ((*from_env)[0], (DiscoveryServer{0, "10.9.9.9", 1111}));
}

TEST_F(ContractDiscoveryEnv, NoServersAnywhereMeansSimpleDiscovery) {
  const auto list = dh3::contract::choose_discovery_servers({});
  ASSERT_TRUE(list.ok());
  EXPECT_TRUE(list->empty());
  auto qos = dh3::contract::participant_qos("x", {});
  ASSERT_TRUE(dh3::contract::use_discovery_servers(qos, *list));
  EXPECT_EQ(qos.wire_protocol().builtin.discovery_config.discoveryProtocol,
            rtps::DiscoveryProtocol_t::SIMPLE);
}

TEST_F(ContractDiscoveryEnv, ABadEnvironmentValueIsAnErrorThatNamesTheVariable) {
  ::setenv("ROS_DISCOVERY_SERVER", "10.0.0.1:notaport", 1);
  const auto list = dh3::contract::choose_discovery_servers({});
  ASSERT_FALSE(list.ok());
  EXPECT_EQ(list.error().rfind("ROS_DISCOVERY_SERVER: ", 0), 0U) << list.error();
}

TEST(ContractUseDiscoveryServers, MakesTheParticipantAClientOfEachServer) {
  auto qos = dh3::contract::participant_qos("x", {});
  ASSERT_TRUE(
      dh3::contract::use_discovery_servers(qos, {{0, "10.0.0.1", 11811}, {3, "10.0.0.4", 12000}}));
  const auto& config = qos.wire_protocol().builtin.discovery_config;
  EXPECT_EQ(config.discoveryProtocol, rtps::DiscoveryProtocol_t::CLIENT);
  ASSERT_EQ(config.m_DiscoveryServers.size(), 2U);

  rtps::GuidPrefix_t id3;
  ASSERT_TRUE(rtps::get_server_client_default_guidPrefix(3, id3));
  const auto& second = config.m_DiscoveryServers.back();
  EXPECT_EQ(second.guidPrefix, id3);
  ASSERT_EQ(second.metatrafficUnicastLocatorList.size(), 1U);
  const auto& locator = *second.metatrafficUnicastLocatorList.begin();
  EXPECT_EQ(rtps::IPLocator::ip_to_string(locator), "10.0.0.4");
  EXPECT_EQ(locator.port, 12000U);
}

// A free UDP port on loopback for the server (it may be taken again before
// the server binds it; the test would then fail, not pass wrongly).
std::uint16_t free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  ::close(fd);
  return ntohs(address.sin_port);
}

// Two participants that are clients of a server do not find each other while
// it is not running, even though two participants using simple discovery on
// the same loopback find each other meanwhile; once the server runs, they do.
TEST_F(ContractDiscoveryEnv, ClientsFindEachOtherOnlyThroughTheServer) {
  using dh3::test::ContractParticipant;
  const int domain = dh3::test::contract_test_domain();
  const std::uint16_t port = free_udp_port();
  const auto servers =
      dh3::contract::parse_discovery_server_list("127.0.0.1:" + std::to_string(port));
  ASSERT_TRUE(servers.ok()) << servers.error();

  // UDP only: shared memory needs no discovery traffic on the network but is
  // found through it all the same; this keeps every participant on loopback.
  const dh3::contract::TransportOptions udp{{}, true};
  auto client_qos = [&](const std::string& name) {
    auto qos = dh3::contract::participant_qos(name, udp);
    EXPECT_TRUE(dh3::contract::use_discovery_servers(qos, *servers));
    return qos;
  };
  ContractParticipant publisher(domain, client_qos("ds-client-pub"));
  ContractParticipant subscriber(domain, client_qos("ds-client-sub"));
  ASSERT_TRUE(publisher.created());
  ASSERT_TRUE(subscriber.created());
  auto* writer = publisher.writer(dh3::topics::HAND_EVENT);
  auto* reader = subscriber.reader(dh3::topics::HAND_EVENT);
  ASSERT_NE(writer, nullptr);
  ASSERT_NE(reader, nullptr);

  ContractParticipant simple_publisher(domain,
                                       dh3::contract::participant_qos("ds-simple-pub", udp));
  ContractParticipant simple_subscriber(domain,
                                        dh3::contract::participant_qos("ds-simple-sub", udp));
  // Another topic: whether or not a client would take a simple participant's
  // announcement, these endpoints are no match for the clients' ones.
  auto* simple_writer = simple_publisher.writer(dh3::topics::HAND_STATUS);
  auto* simple_reader = simple_subscriber.reader(dh3::topics::HAND_STATUS);
  ASSERT_NE(simple_writer, nullptr);
  ASSERT_NE(simple_reader, nullptr);
  // Simple discovery finds its peers; a client's writer sees no one at all.
  ASSERT_TRUE(dh3::test::eventually([&] { return dh3::test::matched(simple_reader) >= 1; }));
  EXPECT_EQ(dh3::test::matched(writer), 0);
  EXPECT_EQ(dh3::test::matched(reader), 0);

  dh3::test::Process server(DH3_DISCOVERY_SERVER_PATH,
                            {"-i", "0", "-l", "127.0.0.1", "-p", std::to_string(port)},
                            dh3::test::Process::Stdin::dev_null);
  ASSERT_TRUE(server.started());
  EXPECT_TRUE(dh3::test::eventually([&] {
    return dh3::test::matched(writer) == 1 && dh3::test::matched(reader) == 1;
  })) << "the clients did not find each other through the discovery server on port "
      << port;
}

}  // namespace
