// dh3/contract/security.hpp with the PKI deploy/security/make-test-pki.sh makes, in
// Fast DDS itself: who may create which writer and reader, that authenticated
// participants get each other's data and that a participant without
// credentials gets none.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "contract_participant.hpp"
#include "dh3/contract/participant_setup.hpp"
#include "dh3/contract/security.hpp"
#include "support/process.hpp"
#include "support/test_pki.hpp"

namespace {

namespace fs = std::filesystem;
using dh3::test::ContractParticipant;
using dh3::test::eventually;
using dh3::test::matched;

class ContractSecurity : public ::testing::Test {
 protected:
  // One PKI for the whole suite: making keys is the slow part.
  static void SetUpTestSuite() {
    dir_ = dh3::test::make_test_pki(DH3_MAKE_TEST_PKI, dh3::test::contract_test_domain(),
                                    "contract");
    made_ = !dir_.empty();
  }
  static void TearDownTestSuite() { dh3::test::remove_test_pki(dir_); }
  void SetUp() override { ASSERT_TRUE(made_) << "make-test-pki.sh failed into " << dir_; }

  static eprosima::fastdds::dds::DomainParticipantQos qos(const std::string& identity) {
    auto qos = dh3::contract::participant_qos("dh3-contract " + identity, {});
    dh3::contract::enable_security(qos, dh3::contract::security_files_in(dir_, identity));
    return qos;
  }

  const int domain_ = dh3::test::contract_test_domain();
  static inline std::string dir_;
  static inline bool made_ = false;
};

TEST_F(ContractSecurity, TheScriptsLayoutIsWhatTheHelperNames) {
  for (const std::string identity : {"service", "operator", "monitor"}) {
    const auto files = dh3::contract::security_files_in(dir_, identity);
    EXPECT_TRUE(files.wanted());
    const auto readable = dh3::contract::check_security_files(files);
    EXPECT_TRUE(readable.ok()) << identity << ": " << readable.error();
  }
}

TEST_F(ContractSecurity, AMissingFileIsNamed) {
  auto files = dh3::contract::security_files_in(dir_, "nobody");
  const auto missing = dh3::contract::check_security_files(files);
  ASSERT_FALSE(missing.ok());
  const auto& message = missing.error();
  EXPECT_NE(message.find("identity certificate"), std::string::npos) << message;
  EXPECT_NE(message.find("nobody/cert.pem"), std::string::npos) << message;

  files = dh3::contract::security_files_in(dir_, "service");
  files.governance.clear();
  const auto no_governance = dh3::contract::check_security_files(files);
  ASSERT_FALSE(no_governance.ok());
  EXPECT_EQ(no_governance.error(), "DDS Security: no governance document given");
  EXPECT_FALSE(dh3::contract::SecurityFiles{}.wanted());
}

TEST_F(ContractSecurity, PropertiesSwitchOnTheThreeBuiltinPlugins) {
  const auto properties =
      dh3::contract::security_properties(dh3::contract::security_files_in(dir_, "operator"));
  const auto value = [&](const std::string& name) {
    for (const auto& [n, v] : properties) {
      if (n == name) return v;
    }
    return std::string("<missing>");
  };
  EXPECT_EQ(value("dds.sec.auth.plugin"), "builtin.PKI-DH");
  EXPECT_EQ(value("dds.sec.access.plugin"), "builtin.Access-Permissions");
  EXPECT_EQ(value("dds.sec.crypto.plugin"), "builtin.AES-GCM-GMAC");
  EXPECT_EQ(value("dds.sec.auth.builtin.PKI-DH.private_key"),
            "file://" + (fs::path(dir_) / "operator" / "key.pem").string());
}

// A service on every interface under DDS Security: only holders of the
// cell's certificates can drive the hands, so start-up warns of nothing.
TEST_F(ContractSecurity, ASecuredServiceOnEveryInterfaceIsNotWarnedAbout) {
  dh3::contract::ParticipantOptions options;
  options.interfaces = {"*"};
  options.security_dir = dir_;
  options.security_identity = "service";
  dh3::contract::SetupReport report;
  const auto made = dh3::contract::make_participant_qos(options, report);
  ASSERT_TRUE(made.has_value()) << made.error();
  EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
}

// Credentials that do not belong together: Fast DDS refuses the participant
// rather than run it unauthenticated.
TEST_F(ContractSecurity, ACertificateWithAnotherIdentitysKeyIsRefused) {
  auto files = dh3::contract::security_files_in(dir_, "service");
  files.private_key = dh3::contract::security_files_in(dir_, "operator").private_key;
  auto qos = dh3::contract::participant_qos("dh3-contract mismatched", {});
  dh3::contract::enable_security(qos, files);
  ContractParticipant participant(domain_, qos);
  EXPECT_FALSE(participant.created());
}

TEST_F(ContractSecurity, TheServiceMayPublishStatusEventsInfoRepliesAndReadRequestsOnly) {
  ContractParticipant service(domain_, qos("service"));
  ASSERT_TRUE(service.created());
  EXPECT_NE(service.writer(dh3::topics::HAND_STATUS), nullptr);
  EXPECT_NE(service.writer(dh3::topics::HAND_EVENT), nullptr);
  EXPECT_NE(service.writer(dh3::topics::SERVICE_INFO), nullptr);
  EXPECT_NE(service.writer(dh3::topics::COMMAND_REPLY), nullptr);
  EXPECT_NE(service.reader(dh3::topics::COMMAND_REQUEST), nullptr);
  EXPECT_EQ(service.writer(dh3::topics::COMMAND_REQUEST), nullptr);
  EXPECT_EQ(service.reader(dh3::topics::COMMAND_REPLY), nullptr);
}

TEST_F(ContractSecurity, AnOperatorMayPublishRequestsAndReadEverything) {
  ContractParticipant op(domain_, qos("operator"));
  ASSERT_TRUE(op.created());
  EXPECT_NE(op.writer(dh3::topics::COMMAND_REQUEST), nullptr);
  EXPECT_NE(op.reader(dh3::topics::HAND_STATUS), nullptr);
  EXPECT_NE(op.reader(dh3::topics::HAND_EVENT), nullptr);
  EXPECT_NE(op.reader(dh3::topics::SERVICE_INFO), nullptr);
  EXPECT_NE(op.reader(dh3::topics::COMMAND_REPLY), nullptr);
  EXPECT_EQ(op.writer(dh3::topics::HAND_STATUS), nullptr);
  EXPECT_EQ(op.writer(dh3::topics::COMMAND_REPLY), nullptr);
}

TEST_F(ContractSecurity, AMonitorMayOnlyReadStatusAndEvents) {
  ContractParticipant monitor(domain_, qos("monitor"));
  ASSERT_TRUE(monitor.created());
  EXPECT_NE(monitor.reader(dh3::topics::HAND_STATUS), nullptr);
  EXPECT_NE(monitor.reader(dh3::topics::HAND_EVENT), nullptr);
  EXPECT_EQ(monitor.writer(dh3::topics::COMMAND_REQUEST), nullptr);
  EXPECT_EQ(monitor.reader(dh3::topics::SERVICE_INFO), nullptr);
  EXPECT_EQ(monitor.reader(dh3::topics::COMMAND_REPLY), nullptr);
  EXPECT_EQ(monitor.writer(dh3::topics::HAND_STATUS), nullptr);
}

TEST_F(ContractSecurity, AuthenticatedParticipantsGetTheDataAndOthersNothing) {
  ContractParticipant service(domain_, qos("service"));
  ContractParticipant op(domain_, qos("operator"));
  ContractParticipant monitor(domain_, qos("monitor"));
  ContractParticipant outsider(domain_, dh3::contract::participant_qos("dh3-contract plain", {}));
  ASSERT_TRUE(service.created() && op.created() && monitor.created() && outsider.created());

  auto* status_writer = service.writer(dh3::topics::HAND_STATUS);
  auto* request_reader = service.reader(dh3::topics::COMMAND_REQUEST);
  auto* op_status = op.reader(dh3::topics::HAND_STATUS);
  auto* op_requests = op.writer(dh3::topics::COMMAND_REQUEST);
  auto* monitor_status = monitor.reader(dh3::topics::HAND_STATUS);
  auto* outsider_status = outsider.reader(dh3::topics::HAND_STATUS);
  auto* outsider_requests = outsider.writer(dh3::topics::COMMAND_REQUEST);
  ASSERT_TRUE(status_writer && request_reader && op_status && op_requests && monitor_status &&
              outsider_status && outsider_requests);

  dh3::msg::HandStatus status;
  status.service("cell");
  status.bus("bus0");
  status.can_id(1);
  status.position(42);
  ASSERT_TRUE(status_writer->write(&status));

  std::vector<dh3::msg::HandStatus> at_operator;
  std::vector<dh3::msg::HandStatus> at_monitor;
  ASSERT_TRUE(eventually([&] {
    dh3::test::take_all(op_status, at_operator);
    dh3::test::take_all(monitor_status, at_monitor);
    return !at_operator.empty() && !at_monitor.empty();
  })) << "operator got "
      << at_operator.size() << ", monitor " << at_monitor.size();
  EXPECT_EQ(at_operator.front().position(), 42);
  EXPECT_EQ(at_monitor.front().position(), 42);

  // A request from the operator reaches the service; one the outsider writes
  // (after the operator's, so it had as long to arrive) does not.
  dh3::msg::CommandRequest request;
  request.client_id("outsider");
  request.request_seq(1);
  ASSERT_TRUE(outsider_requests->write(&request));
  request.client_id("operator");
  ASSERT_TRUE(op_requests->write(&request));
  std::vector<dh3::msg::CommandRequest> requests;
  ASSERT_TRUE(eventually([&] {
    dh3::test::take_all(request_reader, requests);
    return !requests.empty();
  }));
  request.client_id("outsider");
  request.request_seq(2);
  ASSERT_TRUE(outsider_requests->write(&request));
  request.client_id("operator");
  ASSERT_TRUE(op_requests->write(&request));
  ASSERT_TRUE(eventually([&] {
    dh3::test::take_all(request_reader, requests);
    return requests.size() >= 2;
  }));
  for (const auto& r : requests) EXPECT_EQ(r.client_id(), "operator");

  // By now the operator and the monitor have had the status; the outsider
  // neither matched the service's writer nor got a sample.
  std::vector<dh3::msg::HandStatus> at_outsider;
  dh3::test::take_all(outsider_status, at_outsider);
  EXPECT_TRUE(at_outsider.empty());
  EXPECT_EQ(matched(outsider_status), 0);
  EXPECT_EQ(matched(outsider_requests), 0);
  EXPECT_EQ(matched(status_writer), 2);  // operator and monitor
}

}  // namespace
