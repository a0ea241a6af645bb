// dh3ctl as a user runs it, as a child process against dh3-service on the
// simulator: exit status, what it prints, --json, errors with the service's
// message, events and status --watch.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "client_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::AllOf;
using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

class Dh3ctlTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(service_.started()); }
  RunningService service_{sim_config()};
};

TEST_F(Dh3ctlTest, ListShowsTheServiceAndEveryHand) {
  const Finished run = dh3ctl({"list"});
  ASSERT_EQ(run.exit_code, 0) << run.text();
  EXPECT_THAT(run.text(), HasSubstr("service " + test_service_name()));
  EXPECT_THAT(run.text(), HasSubstr("bus0 sim"));
  for (std::uint16_t id = 1; id <= 3; ++id) EXPECT_THAT(run.text(), HasSubstr(hand_spec(id)));
}

TEST_F(Dh3ctlTest, InitMoveGraspStatusRelease) {
  const Finished init = dh3ctl({"init", hand_spec(1)});
  ASSERT_EQ(init.exit_code, 0) << init.text();
  EXPECT_THAT(init.text(), HasSubstr(hand_spec(1) + ": initialized"));

  const Finished move = dh3ctl({"move", hand_spec(1), "60"});
  ASSERT_EQ(move.exit_code, 0) << move.text();
  EXPECT_THAT(move.text(), HasSubstr(hand_spec(1) + ": moving to 60"))
      << "accepted, not arrived: it does not say it moved";
  const Finished grasp = dh3ctl({"grasp", hand_spec(1), "40"});
  ASSERT_EQ(grasp.exit_code, 0) << grasp.text();
  EXPECT_THAT(grasp.text(), HasSubstr("GRASPED at position"));
  const Finished grasp_json = dh3ctl({"--json", "grasp", hand_spec(1), "40"});
  ASSERT_EQ(grasp_json.exit_code, 0) << grasp_json.text();
  EXPECT_THAT(grasp_json.text(), HasSubstr(R"("grasp":"GRASPED")"));
  EXPECT_THAT(grasp_json.text(), HasSubstr(R"("position":)")) << "the JSON says where, as the text";

  const Finished status = dh3ctl({"--json", "status", hand_spec(1)});
  ASSERT_EQ(status.exit_code, 0) << status.text();
  ASSERT_EQ(status.lines.size(), 1U) << status.text();
  EXPECT_THAT(status.lines[0], StartsWith(R"({"type":"status","hand":")" + hand_spec(1)));
  EXPECT_THAT(status.lines[0], HasSubstr(R"("initialized":true)"));

  const Finished release = dh3ctl({"release", hand_spec(1), "100"});
  ASSERT_EQ(release.exit_code, 0) << release.text();
}

TEST_F(Dh3ctlTest, ShortHandNamesWorkWhenUnambiguous) {
  const Finished init = dh3ctl({"init", "2"});
  ASSERT_EQ(init.exit_code, 0) << init.text();
  EXPECT_THAT(init.text(), HasSubstr(hand_spec(2)));
  const Finished grasp = dh3ctl({"--json", "grasp", "bus0/2", "30"});
  ASSERT_EQ(grasp.exit_code, 0) << grasp.text();
  EXPECT_THAT(grasp.text(), HasSubstr(R"("grasp":"MISSED")"));
}

TEST_F(Dh3ctlTest, FailuresExitNonZeroWithTheServicesMessage) {
  const Finished early = dh3ctl({"--json", "move", hand_spec(3), "50"});
  EXPECT_EQ(early.exit_code, 1);
  EXPECT_THAT(early.text(), AllOf(HasSubstr(R"("ok":false,"code":"NOT_INITIALIZED")"),
                                  HasSubstr("not initialized")));
  const Finished admin = dh3ctl({"--json", "set-can-id", hand_spec(3), "7", "--yes"});
  EXPECT_EQ(admin.exit_code, 1);
  EXPECT_THAT(admin.text(), HasSubstr(R"("code":"DENIED")"));
  const Finished unknown = dh3ctl({"--json", "init", test_service_name() + "/bus0/9"});
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_THAT(unknown.text(), HasSubstr(R"("code":"UNKNOWN_HAND")"));
}

TEST_F(Dh3ctlTest, VersionReadScanAndForce) {
  const Finished version = dh3ctl({"version", hand_spec(1)});
  ASSERT_EQ(version.exit_code, 0) << version.text();
  EXPECT_THAT(version.text(), HasSubstr("firmware 4.1.2.0 (raw 0x04010200)"));
  const Finished version_json = dh3ctl({"--json", "version", hand_spec(1)});
  ASSERT_EQ(version_json.exit_code, 0) << version_json.text();
  EXPECT_THAT(version_json.text(), HasSubstr(R"("firmware_version_text":"4.1.2.0")"));
  const Finished force = dh3ctl({"force", hand_spec(1), "65", "35"});
  ASSERT_EQ(force.exit_code, 0) << force.text();
  const Finished read = dh3ctl({"read", hand_spec(1), "closing_force"});
  ASSERT_EQ(read.exit_code, 0) << read.text();
  EXPECT_THAT(read.text(), HasSubstr("closing_force (0x0502) = 65"));
  const Finished scan = dh3ctl({"scan"});
  ASSERT_EQ(scan.exit_code, 0) << scan.text();
  EXPECT_THAT(scan.text(), HasSubstr(test_service_name() + "/bus0: found 1 2 3"));
}

TEST_F(Dh3ctlTest, EventsPrintsWhatHappensToTheHand) {
  Process events(DH3CTL_PATH, ctl_args({"events", hand_spec(1), "--count", "1"}),
                 Process::Stdin::dev_null);
  ASSERT_TRUE(events.wait_for_line("watching events", kClientDeadline));
  ASSERT_EQ(dh3ctl({"init", hand_spec(1)}).exit_code, 0);
  const auto line = events.read_line(kClientDeadline);
  ASSERT_TRUE(line);
  EXPECT_THAT(*line, HasSubstr(hand_spec(1)));
  const auto status = events.wait_exit(kClientDeadline);
  ASSERT_TRUE(status && WIFEXITED(*status));
  EXPECT_EQ(WEXITSTATUS(*status), 0);
}

TEST_F(Dh3ctlTest, MoveAndRotateWithWaitSayWhereTheMotionEnded) {
  ASSERT_EQ(dh3ctl({"init", hand_spec(2)}).exit_code, 0);
  const Finished move = dh3ctl({"move", hand_spec(2), "30", "--wait"});
  ASSERT_EQ(move.exit_code, 0) << move.text();
  ASSERT_EQ(move.lines.size(), 2U) << move.text();
  EXPECT_EQ(move.lines[0], hand_spec(2) + ": moving to 30");
  EXPECT_EQ(move.lines[1], hand_spec(2) + ": ARRIVED at 30");
  const Finished rotate = dh3ctl({"--json", "rotate", hand_spec(2), "40", "--wait"});
  ASSERT_EQ(rotate.exit_code, 0) << rotate.text();
  ASSERT_EQ(rotate.lines.size(), 1U) << rotate.text();
  EXPECT_THAT(rotate.lines[0],
              AllOf(HasSubstr(R"("outcome":"ROTATION_ARRIVED")"), HasSubstr(R"("position":40)")));
}

TEST_F(Dh3ctlTest, EventsOfAMotionAreWhereItStoppedAndAStopAtRestReportsNothing) {
  // Hand 2 holds no object: both moves arrive.
  ASSERT_EQ(dh3ctl({"init", hand_spec(2)}).exit_code, 0);
  Process events(DH3CTL_PATH, ctl_args({"events", hand_spec(2)}), Process::Stdin::dev_null);
  ASSERT_TRUE(events.wait_for_line("watching events", kClientDeadline));
  ASSERT_EQ(dh3ctl({"move", hand_spec(2), "50", "--wait"}).exit_code, 0);
  ASSERT_EQ(dh3ctl({"stop", hand_spec(2)}).exit_code, 0);
  ASSERT_EQ(dh3ctl({"move", hand_spec(2), "20", "--wait"}).exit_code, 0);
  // The second arrival is the line after the first; a stop at rest would put
  // an ARRIVED (target 50) between them.
  std::vector<std::string> arrivals;
  std::string seen;
  while (arrivals.size() < 2) {
    const auto line = events.read_line(kClientDeadline);
    ASSERT_TRUE(line) << "events seen:\n" << seen;
    seen += *line + "\n";
    if (line->find(" ARRIVED ") != std::string::npos) arrivals.push_back(*line);
  }
  EXPECT_THAT(arrivals[0], ContainsRegex(" target 50($|:)"));
  EXPECT_THAT(arrivals[1], ContainsRegex(" target 20($|:)")) << "no arrival from the stop at rest";
  // Where each motion stopped, or "-" (not read yet): never where it started.
  EXPECT_THAT(arrivals[0], Not(HasSubstr("position 100 ")));
  EXPECT_THAT(arrivals[1], Not(HasSubstr("position 50 ")));
  events.send_signal(SIGINT);
  const auto status = events.wait_exit(kClientDeadline);
  EXPECT_TRUE(status && WIFEXITED(*status));
}

TEST_F(Dh3ctlTest, StatusWatchStreamsUpdatesUntilInterrupted) {
  Process watch(DH3CTL_PATH, ctl_args({"--json", "status", hand_spec(2), "--watch"}),
                Process::Stdin::dev_null);
  // Not a terminal: one JSON line per status sample, the known one first.
  const auto first = watch.wait_for_line("{", kClientDeadline);
  ASSERT_TRUE(first);
  EXPECT_THAT(*first, HasSubstr(R"("hand":")" + hand_spec(2)));
  ASSERT_EQ(dh3ctl({"init", hand_spec(2)}).exit_code, 0);
  bool saw_initialized = false;
  while (!saw_initialized) {
    const auto line = watch.read_line(kClientDeadline);
    ASSERT_TRUE(line) << "no status update showed the hand initialized";
    saw_initialized = line->find(R"("initialized":true)") != std::string::npos;
  }
  watch.send_signal(SIGINT);
  const auto status = watch.wait_exit(kClientDeadline);
  ASSERT_TRUE(status && WIFEXITED(*status));
  EXPECT_EQ(WEXITSTATUS(*status), 0);
}

/// CPU seconds (user + system) the process `pid` has used so far.
double cpu_seconds(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  // Fields after the command name, which is in parentheses and may hold spaces.
  std::istringstream fields(text.substr(text.rfind(')') + 2));
  std::vector<std::string> field{std::istream_iterator<std::string>(fields), {}};
  if (field.size() < 13) return -1;
  const double ticks = static_cast<double>(::sysconf(_SC_CLK_TCK));
  return (std::stod(field[11]) + std::stod(field[12])) / ticks;
}

TEST_F(Dh3ctlTest, StatusWatchIntoAPipeIdlesWhileNothingChanges) {
  Process watch(DH3CTL_PATH, ctl_args({"--json", "status", hand_spec(2), "--watch"}),
                Process::Stdin::dev_null);
  ASSERT_TRUE(watch.wait_for_line("{", kClientDeadline));
  // A busy loop takes a core, or its share of one on a loaded machine; a
  // waiting watcher takes next to nothing. The window is a sampling interval,
  // not a deadline: a tenth of it is far above what waiting costs and below
  // what spinning gets even with eight busy processes on two cores.
  const double cpu_before = cpu_seconds(watch.pid());
  ASSERT_GE(cpu_before, 0.0);
  const auto started = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const double used = cpu_seconds(watch.pid()) - cpu_before;
  EXPECT_LT(used, wall / 10) << "dh3ctl status --watch used " << used << " s of CPU in " << wall
                             << " s at rest";
  watch.send_signal(SIGINT);
  EXPECT_TRUE(watch.wait_exit(kClientDeadline));
}

TEST(Dh3ctlWithoutServiceTest, NoServiceExitsNonZeroAndSaysSo) {
  const Finished run = run_program(
      DH3CTL_PATH, {"--domain", std::to_string(test_domain()), "--timeout", "1", "--json", "list"});
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_THAT(run.text(), HasSubstr(R"("code":"NO_SERVICE")"));
}

}  // namespace
}  // namespace dh3::test
