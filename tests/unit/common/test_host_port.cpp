// dh3/base/host_port.hpp: the one HOST:PORT grammar of every address dh3 reads.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "dh3/base/host_port.hpp"

namespace dh3 {
namespace {

using ::testing::HasSubstr;

std::string error_of(std::string_view text, const HostPortRules& rules = {}) {
  auto parsed = parse_host_port(text, rules);
  return parsed ? std::string("parsed") : parsed.error();
}

TEST(HostPort, ReadsAHostOrABracketedIpv6AddressAndAPort) {
  auto box = parse_host_port("192.168.1.20:8888");
  ASSERT_TRUE(box) << box.error();
  EXPECT_EQ(box->host, "192.168.1.20");
  EXPECT_EQ(box->port, 8888);
  EXPECT_FALSE(box->bracketed);
  auto named = parse_host_port("box.cell:1");
  ASSERT_TRUE(named);
  EXPECT_EQ(named->host, "box.cell");
  auto v6 = parse_host_port("[fe80::1]:65535");
  ASSERT_TRUE(v6);
  EXPECT_EQ(v6->host, "fe80::1");
  EXPECT_EQ(v6->port, 65535);
  EXPECT_TRUE(v6->bracketed);
  EXPECT_EQ(v6->written_host(), "[fe80::1]");
}

TEST(HostPort, SaysWhatIsMissingOrWrong) {
  EXPECT_THAT(error_of("box"), HasSubstr("missing port"));
  EXPECT_THAT(error_of("box:"), HasSubstr("missing port"));
  EXPECT_THAT(error_of("[::1]9000"), HasSubstr("missing port"));
  EXPECT_THAT(error_of("[::1]"), HasSubstr("missing port"));
  EXPECT_THAT(error_of(":9000"), HasSubstr("missing host"));
  EXPECT_THAT(error_of("[]:9000"), HasSubstr("missing host"));
  EXPECT_THAT(error_of("box:90a"), HasSubstr("port '90a' is not a number"));
  EXPECT_THAT(error_of("box:-1"), HasSubstr("port '-1' is not a number"));
  EXPECT_THAT(error_of("box: 80"), HasSubstr("port ' 80' is not a number"));
  EXPECT_THAT(error_of("box:0"), HasSubstr("port 0 is out of range 1-65535"));
  EXPECT_THAT(error_of("box:65536"), HasSubstr("port 65536 is out of range 1-65535"));
  EXPECT_THAT(error_of("box:99999999999999999999"), HasSubstr("out of range 1-65535"));
  EXPECT_THAT(error_of("::1:9000"), HasSubstr("an IPv6 address must be in brackets"));
  EXPECT_THAT(error_of("[::1:9000"), HasSubstr("missing ']'"));
}

TEST(HostPort, ListeningAddressesMayAskForAnyFreePort) {
  EXPECT_THAT(error_of("127.0.0.1:0"), HasSubstr("out of range 1-65535"));
  auto any = parse_host_port("127.0.0.1:0", {.port_zero = true});
  ASSERT_TRUE(any) << any.error();
  EXPECT_EQ(any->port, 0);
  EXPECT_THAT(error_of("127.0.0.1:65536", {.port_zero = true}), HasSubstr("out of range 0-65535"));
}

TEST(HostPort, TheCallerMayLetThePortOrTheHostBeLeftOut) {
  auto server = parse_host_port("10.0.0.2", {.default_port = 11811});
  ASSERT_TRUE(server) << server.error();
  EXPECT_EQ(server->host, "10.0.0.2");
  EXPECT_EQ(server->port, 11811);
  auto given = parse_host_port("10.0.0.2:7400", {.default_port = 11811});
  ASSERT_TRUE(given);
  EXPECT_EQ(given->port, 7400);
  auto any_host = parse_host_port(":9000", {.port_zero = true, .empty_host = true});
  ASSERT_TRUE(any_host) << any_host.error();
  EXPECT_EQ(any_host->host, "");
  EXPECT_EQ(any_host->port, 9000);
  EXPECT_THAT(error_of("[]:9000", {.empty_host = true}), HasSubstr("missing host"));
}

TEST(HostPort, OnlyLoopbackAddressesStayOnThisMachine) {
  for (const char* host : {"127.0.0.1", "127.1.2.3", "::1", "localhost"}) {
    EXPECT_TRUE(is_loopback_host(host)) << host;
  }
  for (const char* host : {"0.0.0.0", "::", "10.0.0.2", "169.254.1.1", "128.0.0.1", "fe80::1",
                           "localhost.example.com", "", "127.0.0.1:80"}) {
    EXPECT_FALSE(is_loopback_host(host)) << host;
  }
}

TEST(HostPort, AnAddressIsWrittenBackAsItIsParsed) {
  EXPECT_EQ(host_port_text("192.168.1.20", 8886), "192.168.1.20:8886");
  EXPECT_EQ(host_port_text("box.local", 8886), "box.local:8886");
  EXPECT_EQ(host_port_text("::1", 8886), "[::1]:8886");
  for (const char* written : {"192.168.1.20:8886", "[fe80::1]:7000"}) {
    const auto parsed = parse_host_port(written);
    ASSERT_TRUE(parsed) << written;
    EXPECT_EQ(host_port_text(parsed->host, parsed->port), written);
  }
}

}  // namespace
}  // namespace dh3
