// The flight recorder and its replay through the real programs: dh3-service
// records a session on dh3-sim (initialize, move, a grasp that catches, the
// part slipping out), can-utils' log2asc reads the recording, and dh3-sim
// --replay serves it to a fresh dh3-service: a client doing the same sees the
// same events in the same order, although no hand is simulated any more.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "service_fixture.hpp"
#include "support/metrics_scrape.hpp"

namespace dh3::test {
namespace {

using ::testing::StartsWith;

std::string session_config(const std::string& spec, const std::string& record_dir) {
  std::string config = "buses:\n  - name: box\n    spec: " + spec +
                       "\n    command_interval_ms: 2\n    poll_interval_moving_ms: 20\n"
                       "    poll_interval_idle_ms: 50\n    reply_timeout_ms: 100\n"
                       "    hands: [{id: 1}]\n";
  if (!record_dir.empty()) config += "    record: {dir: " + record_dir + "}\n";
  return config;
}

/// What a client saw of one session.
struct Session {
  std::vector<msg::CommandReply> replies;
  std::vector<msg::EventKind> events;  ///< hand 1's after it came online, up to its drop
  std::optional<int> service_exit;
};

/// Runs the session against `spec` (recording into `record_dir` if given,
/// with --record): initialize, move to 70, grasp (the part at 40 is caught),
/// then waits for the drop, which `drop` causes (the recording's dh3-sim) or
/// the replay brings by itself.
Session run_session(const std::string& spec, const std::string& record_dir,
                    const std::function<void()>& drop) {
  Session session;
  TempFile config(session_config(spec, {}));
  std::vector<std::string> args{"--config", config.path()};
  if (!record_dir.empty()) args.insert(args.end(), {"--record", record_dir});
  ServiceProcess service(args);
  EXPECT_TRUE(service.started());
  auto client = connected_client(service.name());
  EXPECT_TRUE(client);
  if (!client) return session;
  const auto hand = DdsTestClient::hand(service.name(), "box", 1);
  EXPECT_TRUE(client->wait_status(hand, [](const auto& s) { return s.online(); }));
  for (const auto& [command, value] : std::vector<std::pair<msg::CommandType, std::int32_t>>{
           {msg::INITIALIZE, 0}, {msg::MOVE, 70}, {msg::GRASP, 40}}) {
    auto reply = client->call(hand, command, value);
    EXPECT_TRUE(reply) << "no reply to command " << static_cast<int>(command);
    if (reply) session.replies.push_back(*reply);
  }
  drop();
  const auto dropped = client->wait_event([](const msg::HandEvent& e) {
    return e.hand().can_id() == 1 && e.kind() == msg::EVENT_DROPPED;
  });
  EXPECT_TRUE(dropped) << "no DROPPED event";
  for (const msg::HandEvent& event : client->events()) {
    if (event.hand().can_id() != 1) continue;
    // The hand coming online at the service's start reaches a client that
    // subscribed early enough only: not the hand's doing.
    if (session.events.empty() && event.kind() == msg::EVENT_ONLINE) continue;
    session.events.push_back(event.kind());
    if (event.kind() == msg::EVENT_DROPPED) break;
  }
  session.service_exit = service.stop();  // the recorder writes what it holds
  return session;
}

/// Runs a shell command; its exit status and output.
std::pair<int, std::vector<std::string>> run(const std::string& command) {
  Process shell("/bin/sh", {"-c", command + " 2>&1"}, Process::Stdin::dev_null);
  std::vector<std::string> lines;
  while (auto line = shell.read_line(std::chrono::seconds(20))) lines.push_back(*line);
  const auto status = shell.wait_exit(std::chrono::seconds(20));
  return {status && WIFEXITED(*status) ? WEXITSTATUS(*status) : -1, lines};
}

std::vector<std::string> frame_lines(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with("(")) lines.push_back(line);
  }
  return lines;
}

class RecordReplayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = "/tmp/dh3-record-" + std::to_string(::getpid()) + "-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
  std::filesystem::path dir_;
};

TEST_F(RecordReplayTest, AReplayedRecordingGivesTheClientTheSameEventsInTheSameOrder) {
  Session recorded;
  {
    SimProcess sim({"--hands", "1", "--object", "1:40", "--init-time-ms", "50",
                    "--reply-delay-ms", "1"});
    ASSERT_NE(sim.port(), 0) << "dh3-sim did not start";
    recorded = run_session(sim.bus_spec(), dir_.string(),
                           [&] { EXPECT_THAT(sim.control("drop 1"), StartsWith("ok")); });
  }
  ASSERT_EQ(recorded.service_exit, 0);
  ASSERT_EQ(recorded.replies.size(), 3U);
  EXPECT_EQ(recorded.replies[2].grasp(), msg::GRASPED);
  EXPECT_THAT(recorded.events, ::testing::IsSupersetOf({msg::EVENT_INITIALIZED,
                                                        msg::EVENT_GRASPED, msg::EVENT_DROPPED}));

  // One file, every line a frame with its direction, and can-utils reads it.
  const std::filesystem::path file = dir_ / "box.000001.log";
  ASSERT_TRUE(std::filesystem::exists(file));
  const auto lines = frame_lines(file);
  ASSERT_GT(lines.size(), 20U);
  for (const std::string& line : lines) {
    ASSERT_TRUE(line.ends_with(" T") || line.ends_with(" R")) << line;
  }
  const auto [status, asc] = run("log2asc -I " + file.string() + " box");
  ASSERT_EQ(status, 0) << ::testing::PrintToString(asc);
  const auto count = [&](const char* direction) {
    return std::count_if(asc.begin(), asc.end(), [&](const std::string& l) {
      return l.find(direction) != std::string::npos;
    });
  };
  EXPECT_GT(count(" Tx "), 0);
  EXPECT_GT(count(" Rx "), 0);
  EXPECT_EQ(static_cast<std::size_t>(count(" Tx ") + count(" Rx ")), lines.size());

  // The desk: the recording alone answers the service.
  Session replayed;
  {
    SimProcess replay({"--replay", file.string()});
    ASSERT_NE(replay.port(), 0) << "dh3-sim --replay did not start";
    EXPECT_THAT(replay.control("drop 1"), StartsWith("error"));  // the recording decides
    replayed = run_session(replay.bus_spec(), {}, [] {});
  }
  EXPECT_EQ(replayed.service_exit, 0);
  EXPECT_EQ(replayed.events, recorded.events);
  ASSERT_EQ(replayed.replies.size(), recorded.replies.size());
  for (std::size_t i = 0; i < recorded.replies.size(); ++i) {
    EXPECT_EQ(replayed.replies[i].code(), recorded.replies[i].code()) << "command " << i;
    EXPECT_EQ(replayed.replies[i].grasp(), recorded.replies[i].grasp()) << "command " << i;
  }
}

TEST_F(RecordReplayTest, TheMetricsCountWhatTheRecorderWrote) {
  SimProcess sim({"--hands", "1", "--init-time-ms", "50"});
  ASSERT_NE(sim.port(), 0);
  TempFile config(session_config(sim.bus_spec(), dir_.string()));
  MetricsService service(config.path());
  ASSERT_NE(service.port(), 0);
  const std::string text = scrape_until(service.port(), [](const std::string& t) {
    return metric_value(t, R"(dh3_recorder_frames_total{bus="box"})").value_or(0) >= 10;
  });
  EXPECT_GE(metric_value(text, R"(dh3_recorder_frames_total{bus="box"})").value_or(0), 10) << text;
  EXPECT_EQ(metric_value(text, R"(dh3_recorder_dropped_total{bus="box"})"), 0.0);
  EXPECT_EQ(metric_value(text, R"(dh3_recorder_files_total{bus="box"})"), 1.0);
  EXPECT_GT(metric_value(text, R"(dh3_recorder_bytes_total{bus="box"})").value_or(0), 0);
  ASSERT_EQ(service.stop(), 0);
  EXPECT_GE(frame_lines(dir_ / "box.000001.log").size(), 10U);
}

}  // namespace
}  // namespace dh3::test
