// One set of DDS options for every dh3 program: the same names fill a
// ParticipantOptions (dh3-service) or any struct with its members (the client
// library's ClientOptions); checked as CLI11 parses, or left to the caller.
#include "dh3/contract/participant_flags.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "dh3/contract/participant_checks.hpp"
#include "dh3/contract/participant_options.hpp"

namespace dh3::contract {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

/// What parsing `args` gave: the options, or CLI11's message.
struct Parsed {
  ParticipantOptions options;
  std::string error;
  bool domain_given = false;
};

Parsed parse(std::vector<std::string> args, FlagChecks checks) {
  Parsed parsed;
  parsed.options.security_identity = "operator";
  CLI::App app{"test"};
  const auto given = add_participant_options(app, fields_of(parsed.options), checks);
  args.insert(args.begin(), "test");
  std::vector<const char*> argv;
  for (const auto& arg : args) argv.push_back(arg.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& error) {
    parsed.error = error.what();
  }
  parsed.domain_given = given.domain->count() > 0;
  return parsed;
}

TEST(ParticipantFlags, EveryOptionFillsItsMember) {
  const auto parsed =
      parse({"--domain", "7", "-i", "127.0.0.1", "--udp-only", "--discovery-server",
             "127.0.0.1:11811", "--discovery-server", "", "--profile", "p", "--security-identity",
             "monitor"},
            FlagChecks::on_parse);
  ASSERT_EQ(parsed.error, "");
  EXPECT_TRUE(parsed.domain_given);
  EXPECT_EQ(parsed.options.domain, 7);
  EXPECT_THAT(parsed.options.interfaces, ElementsAre("127.0.0.1"));
  EXPECT_TRUE(parsed.options.udp_only);
  EXPECT_FALSE(parsed.options.shared_memory);
  EXPECT_THAT(parsed.options.discovery_servers, ElementsAre("127.0.0.1:11811", ""));
  EXPECT_EQ(parsed.options.xml_profile, "p");
  EXPECT_EQ(parsed.options.security_identity, "monitor");
}

TEST(ParticipantFlags, BadValuesAreRefusedWithTheContractsWords) {
  EXPECT_THAT(parse({"--domain", "233"}, FlagChecks::on_parse).error,
              AllOf(HasSubstr("--domain"), HasSubstr(check_domain(233).error())));
  EXPECT_THAT(parse({"-i", "eth0"}, FlagChecks::on_parse).error,
              AllOf(HasSubstr("--interface"), HasSubstr(check_interface("eth0").error())));
  EXPECT_THAT(parse({"--discovery-server", "10.0.0.1:0"}, FlagChecks::on_parse).error,
              AllOf(HasSubstr("--discovery-server"), HasSubstr("10.0.0.1:0")));
  EXPECT_THAT(parse({"--xml", "/nonexistent/dh3.xml"}, FlagChecks::on_parse).error,
              AllOf(HasSubstr("--xml"), HasSubstr("/nonexistent/dh3.xml")));
  EXPECT_THAT(parse({"--security-identity", "../etc"}, FlagChecks::on_parse).error,
              AllOf(HasSubstr("--security-identity"), HasSubstr("plain name")));
}

// dh3-service checks the values as its configuration keys: CLI11 only parses.
TEST(ParticipantFlags, TheCallerMayCheckInstead) {
  const auto parsed = parse({"--domain", "233", "-i", "eth0"}, FlagChecks::by_caller);
  EXPECT_EQ(parsed.error, "");
  EXPECT_EQ(parsed.options.domain, 233);
  EXPECT_FALSE(check_domain(parsed.options.domain).ok());
}

TEST(ParticipantFlags, TheHelpShowsTheProgramsOwnDefaults) {
  ParticipantOptions options;
  options.security_identity = "service";
  CLI::App app{"test"};
  (void)add_participant_options(app, fields_of(options), FlagChecks::on_parse);
  EXPECT_THAT(app.help(), HasSubstr("(default service)"));
}

TEST(ParticipantChecks, OptionsThatContradictEachOtherAreNamed) {
  ParticipantOptions options;
  options.udp_only = true;
  options.shared_memory = true;
  const auto label = [](std::string_view field) { return "<" + std::string(field) + ">"; };
  auto misfit = check_participant(options, label);
  ASSERT_FALSE(misfit.ok());
  EXPECT_EQ(misfit.error().field, "shared_memory");
  EXPECT_THAT(misfit.error().message, HasSubstr("contradicts <udp_only>"));
  options = {};
  options.xml_profile = "p";
  misfit = check_participant(options, label);
  ASSERT_FALSE(misfit.ok());
  EXPECT_EQ(misfit.error().field, "xml_profile");
  options = {};
  options.interfaces = {"*", "127.0.0.1"};
  EXPECT_EQ(check_participant(options, label).error().field, "interfaces");
}

}  // namespace
}  // namespace dh3::contract
