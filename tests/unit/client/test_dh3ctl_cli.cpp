// dh3ctl's command line, run in-process: help, usage errors, confirmations
// and the failure when no service answers. (Commands against a real service
// are in tests/integration/client.)

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dh3/base/version.hpp"
#include "support/test_domain.hpp"

namespace dh3::ctl {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

/// A domain nobody else in this test run uses: no service is there.
std::string empty_domain() {
  return std::to_string(test::test_domain());
}

struct CtlRun {
  int code = -1;
  std::string out;
  std::string err;
};

CtlRun dh3ctl(std::vector<std::string> args) {
  args.insert(args.begin(), "dh3ctl");
  std::vector<const char*> argv;
  for (const auto& arg : args) argv.push_back(arg.c_str());
  std::ostringstream out;
  std::ostringstream err;
  std::atomic<bool> interrupted{false};
  CtlRun result;
  result.code = dh3::ctl::run(static_cast<int>(argv.size()), argv.data(), out, err, interrupted);
  result.out = out.str();
  result.err = err.str();
  return result;
}

TEST(Dh3ctlCliTest, VersionPrintsTheProjectVersion) {
  const CtlRun run = dh3ctl({"--version"});
  EXPECT_EQ(run.code, kExitOk);
  EXPECT_EQ(run.out, std::string(kVersion) + "\n");
}

TEST(Dh3ctlCliTest, HelpListsEveryCommandAndExitsZero) {
  const CtlRun run = dh3ctl({"--help"});
  EXPECT_EQ(run.code, kExitOk);
  for (const char* command :
       {"list", "status", "init", "move", "rotate", "force", "grasp", "release", "stop", "events",
        "version", "scan", "read", "set-can-id", "set-baud"}) {
    EXPECT_THAT(run.out, HasSubstr(command)) << command;
  }
  for (const char* flag :
       {"--domain", "--timeout", "--json", "--interface", "--udp-only", "--discovery-server",
        "--xml", "--profile", "--security-dir", "--security-identity"}) {
    EXPECT_THAT(run.out, HasSubstr(flag)) << flag;
  }
}

TEST(Dh3ctlCliTest, EveryCommandHasHelp) {
  for (const char* command :
       {"list", "status", "init", "move", "rotate", "force", "grasp", "release", "stop", "events",
        "version", "scan", "read", "set-can-id", "set-baud"}) {
    const CtlRun run = dh3ctl({command, "--help"});
    EXPECT_EQ(run.code, kExitOk) << command;
    EXPECT_THAT(run.out, HasSubstr("Usage")) << command;
  }
}

TEST(Dh3ctlCliTest, UsageErrorsExitTwo) {
  EXPECT_EQ(dh3ctl({}).code, kExitUsage);                       // no command
  EXPECT_EQ(dh3ctl({"move", "cell/bus0/1"}).code, kExitUsage);  // no position
  EXPECT_EQ(dh3ctl({"move", "cell/bus0/1", "high"}).code, kExitUsage);
  EXPECT_EQ(dh3ctl({"fly"}).code, kExitUsage);
  EXPECT_EQ(dh3ctl({"--domain", "300", "list"}).code, kExitUsage);
}

TEST(Dh3ctlCliTest, AdministrativeCommandsNeedYes) {
  for (const char* command : {"set-can-id", "set-baud"}) {
    const CtlRun run = dh3ctl({command, "cell/bus0/1", "2"});
    EXPECT_EQ(run.code, kExitUsage) << command;
    EXPECT_THAT(run.err, HasSubstr("--yes")) << command;
  }
}

TEST(Dh3ctlCliTest, OutOfRangeValueFailsAtOnceWithTheRange) {
  // Refused by the client library before anything is sent: no service needed.
  const CtlRun run = dh3ctl({"--domain", empty_domain(), "move", "cell/bus0/1", "150"});
  EXPECT_EQ(run.code, kExitFailed);
  EXPECT_THAT(run.err, HasSubstr("INVALID_ARGUMENT"));
  EXPECT_THAT(run.err, HasSubstr("(0-100)"));
}

TEST(Dh3ctlCliTest, NoServiceFailsWithAMessageNamingTheDomain) {
  const CtlRun run = dh3ctl({"--domain", empty_domain(), "--timeout", "0.5", "list"});
  EXPECT_EQ(run.code, kExitFailed);
  EXPECT_THAT(run.err, HasSubstr("NO_SERVICE"));
  EXPECT_THAT(run.err, HasSubstr("domain " + empty_domain()));
}

TEST(Dh3ctlCliTest, JsonFailureIsStillOneObjectOnStdout) {
  const CtlRun run =
      dh3ctl({"--domain", empty_domain(), "--timeout", "0.5", "--json", "init", "cell/bus0/1"});
  EXPECT_EQ(run.code, kExitFailed);
  EXPECT_THAT(run.out, StartsWith(R"({"type":"reply","command":"init","hand":"cell/bus0/1",)"
                                  R"("ok":false,"code":"NO_SERVICE")"));
  EXPECT_EQ(run.out.find('\n'), run.out.size() - 1);  // exactly one line
}

TEST(Dh3ctlCliTest, GlobalOptionsMayFollowTheCommand) {
  const CtlRun run = dh3ctl({"list", "--domain", empty_domain(), "--timeout", "0.2", "--json"});
  EXPECT_EQ(run.code, kExitFailed);
  EXPECT_THAT(run.out, HasSubstr(R"("code":"NO_SERVICE")"));
}

TEST(Dh3ctlCliTest, SecurityCredentialsThatAreNotThereAreReported) {
  // No such directory: a usage error, before any participant.
  EXPECT_EQ(dh3ctl({"--security-dir", "/nonexistent/dh3-pki", "list"}).code, kExitUsage);
  // A directory without the identity's files: the library says which file.
  const std::string dir = ::testing::TempDir();
  const CtlRun run = dh3ctl({"--domain", empty_domain(), "--security-dir", dir,
                             "--security-identity", "monitor", "list"});
  EXPECT_EQ(run.code, kExitFailed);
  EXPECT_THAT(run.err, HasSubstr("DDS Security"));
  EXPECT_THAT(run.err, HasSubstr("identity 'monitor'"));
}

}  // namespace
}  // namespace dh3::ctl
