// dh3-service's deployment settings as a user meets them at start-up: a Fast
// DDS XML profile, discovery servers (ROS_DISCOVERY_SERVER) and DDS Security
// credentials. Wrong settings end start-up with code 1 and a message that says
// what is wrong; discovery through a server and security between hosts are
// tested in tests/netns.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "service_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::HasSubstr;

/// Runs dh3-service (with `env` before it) with stderr joined to stdout; its
/// exit code and output.
std::pair<int, std::string> run_to_exit(const std::string& args, const std::string& env = {}) {
  Process shell("/bin/sh",
                {"-c", env + " " + std::string(DH3_SERVICE_PATH) + " --domain " +
                           std::to_string(test_domain()) + " " + args + " 2>&1"},
                Process::Stdin::dev_null);
  std::string output;
  while (auto line = shell.read_line(std::chrono::seconds(20))) output += *line + "\n";
  const auto status = shell.wait_exit(std::chrono::seconds(20));
  return {status && WIFEXITED(*status) ? WEXITSTATUS(*status) : -1, output};
}

/// Credentials in make-test-pki.sh's layout whose files exist but are no
/// certificates or keys at all.
class BogusCredentials {
 public:
  BogusCredentials() {
    char pattern[] = "/tmp/dh3-bogus-pki-XXXXXX";
    dir_ = ::mkdtemp(pattern);
    std::filesystem::create_directories(dir_ / "service");
    for (const char* file : {"identity_ca.pem", "permissions_ca.pem", "governance.p7s",
                             "service/cert.pem", "service/key.pem", "service/permissions.p7s"}) {
      std::ofstream(dir_ / file) << "not a credential\n";
    }
  }
  ~BogusCredentials() { std::filesystem::remove_all(dir_); }
  BogusCredentials(const BogusCredentials&) = delete;
  BogusCredentials& operator=(const BogusCredentials&) = delete;
  [[nodiscard]] std::string path() const { return dir_.string(); }

 private:
  std::filesystem::path dir_;
};

TEST(ServiceDeployment, CredentialsFastDdsRefusesEndStartUp) {
  const BogusCredentials pki;
  const auto [code, output] = run_to_exit("--security-dir " + pki.path());
  EXPECT_EQ(code, 1);
  EXPECT_THAT(output, HasSubstr("DDS Security did not accept the credentials of identity "
                                "'service' in '" +
                                pki.path() + "'"));
}

/// A test PKI (deploy/security/make-test-pki.sh) in a temporary directory,
/// whose service identity may publish what the service publishes but not
/// subscribe to command requests: its permissions are rewritten and signed
/// again by the test PKI's permissions CA, as an administrator might get them
/// wrong.
class PkiWithoutRequestPermission {
 public:
  PkiWithoutRequestPermission() {
    char pattern[] = "/tmp/dh3-pki-XXXXXX";
    if (::mkdtemp(pattern) == nullptr) return;
    dir_ = pattern;
    const std::string script = std::string(DH3_SOURCE_DIR) + "/deploy/security/make-test-pki.sh";
    if (!succeeded(script + " --domains " + std::to_string(test_domain()) + " " + dir_.string()))
      return;
    const auto permissions = dir_ / "service" / "permissions.xml";
    std::stringstream text;
    text << std::ifstream(permissions).rdbuf();
    std::string xml = text.str();
    const std::string granted = "<subscribe><topics><topic>dh3/command_request</topic>";
    const auto at = xml.find(granted);
    if (at == std::string::npos) return;
    xml.replace(at, granted.size(), "<subscribe><topics><topic>dh3/not_the_requests</topic>");
    std::ofstream(permissions) << xml;
    made_ = succeeded("openssl smime -sign -text -in " + permissions.string() + " -out " +
                      (dir_ / "service" / "permissions.p7s").string() + " -signer " +
                      (dir_ / "permissions_ca.pem").string() + " -inkey " +
                      (dir_ / "ca" / "permissions_ca.key.pem").string());
  }
  ~PkiWithoutRequestPermission() {
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  PkiWithoutRequestPermission(const PkiWithoutRequestPermission&) = delete;
  PkiWithoutRequestPermission& operator=(const PkiWithoutRequestPermission&) = delete;
  [[nodiscard]] bool made() const { return made_; }
  [[nodiscard]] std::string path() const { return dir_.string(); }

 private:
  static bool succeeded(const std::string& command) {
    Process shell("/bin/sh", {"-c", command + " >/dev/null 2>&1"}, Process::Stdin::dev_null);
    const auto status = shell.wait_exit(std::chrono::seconds(120));
    return status && WIFEXITED(*status) && WEXITSTATUS(*status) == 0;
  }

  std::filesystem::path dir_;
  bool made_ = false;
};

// A request reader the service cannot create would leave it running without
// ever answering: start-up ends instead, saying which entity and why.
TEST(ServiceDeployment, PermissionsWithoutTheRequestTopicEndStartUp) {
  const PkiWithoutRequestPermission pki;
  if (!pki.made()) GTEST_SKIP() << "cannot make a test PKI here (openssl?)";
  const auto [code, output] = run_to_exit("--bus sim:1 --security-dir " + pki.path());
  EXPECT_EQ(code, 1) << output;
  EXPECT_THAT(output, HasSubstr("cannot create the reader of dh3/command_request"));
  EXPECT_THAT(output, HasSubstr("permissions of identity 'service' in '" + pki.path() + "'"));
}

TEST(ServiceDeployment, MissingCredentialsAreAConfigError) {
  const BogusCredentials pki;
  const auto [code, output] =
      run_to_exit("--security-dir " + pki.path() + " --security-identity operator");
  EXPECT_EQ(code, 2);
  EXPECT_THAT(output, HasSubstr("--security-dir"));
  EXPECT_THAT(output, HasSubstr(pki.path() + "/operator/cert.pem"));
}

TEST(ServiceDeployment, BadRosDiscoveryServerEndsStartUp) {
  const auto [code, output] = run_to_exit("", "ROS_DISCOVERY_SERVER=127.0.0.1:99999");
  EXPECT_EQ(code, 1);
  EXPECT_THAT(output, HasSubstr("ROS_DISCOVERY_SERVER"));
  EXPECT_THAT(output, HasSubstr("127.0.0.1:99999"));
}

TEST(ServiceDeployment, BadDiscoveryServerOptionIsAConfigError) {
  const auto [code, output] = run_to_exit("--discovery-server 127.0.0.1:0");
  EXPECT_EQ(code, 2);
  EXPECT_THAT(output, HasSubstr("--discovery-server"));
}

TEST(ServiceDeployment, UnknownXmlProfileEndsStartUp) {
  const std::string xml = std::string(DH3_SOURCE_DIR) + "/deploy/dds/udp_only.xml";
  const auto [code, output] = run_to_exit("--xml " + xml + " --profile no_such_profile");
  EXPECT_EQ(code, 1);
  EXPECT_THAT(output, HasSubstr("no participant profile 'no_such_profile' in '" + xml + "'"));
}

// The participant's QoS from the user's own profile: UDP on loopback only (the
// test client's transport), the profile chosen by name: the file's default
// profile has no transport at all, so with it nothing would be seen.
TEST(ServiceDeployment, ServesHandsWithAnXmlProfile) {
  const TempFile xml(R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <transport_descriptors>
      <transport_descriptor>
        <transport_id>loopback_udp</transport_id>
        <type>UDPv4</type>
        <interfaceWhiteList><address>127.0.0.1</address></interfaceWhiteList>
      </transport_descriptor>
    </transport_descriptors>
    <participant profile_name="silent" is_default_profile="true">
      <rtps><useBuiltinTransports>false</useBuiltinTransports></rtps>
    </participant>
    <participant profile_name="loopback">
      <rtps>
        <userTransports><transport_id>loopback_udp</transport_id></userTransports>
        <useBuiltinTransports>false</useBuiltinTransports>
      </rtps>
    </participant>
  </profiles>
</dds>
)",
                     ".xml");
  ServiceProcess service({"--xml", xml.path(), "--profile", "loopback"});
  auto client = connected_client(service.name());
  ASSERT_TRUE(client);
  EXPECT_TRUE(client->wait_status(DdsTestClient::hand(service.name(), "bus0", 1),
                                  [](const auto& s) { return s.online(); }));
  EXPECT_EQ(service.stop(), 0);
}

}  // namespace
}  // namespace dh3::test
