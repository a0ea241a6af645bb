// The real dh3-sim process, driven as a transfer box by a client written from
// the protocol document alone: raw TCP, raw bytes, no project codec. Every
// example frame of docs/dh3-protocol.md is sent with the hand in the state the
// example describes, and the document's reply is expected byte for byte.
//
// Feedback (0x0F) examples: the document prints "arrived" and "caught" with the
// status in the reserve byte (`0F 01 00 02 00 00 00 00`), one place before the
// data field where every other example carries its value. docs/protocol-notes.md reading 2
// takes the data field as the status (the vendor's driver requires reserve 0
// and reads the data field, which only works if hands send it there), so the
// sim answers `0F 01 00 00 02 00 00 00`; these tests expect that form.

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "support/process.hpp"
#include "support/raw_tcp_client.hpp"

namespace {

using namespace std::chrono_literals;
using dh3::test::Process;
using dh3::test::RawTcpClient;

constexpr auto kDeadline = 10s;
constexpr std::size_t kFrame = 14;

/// One dh3-sim process with a client connected to it.
class Dh3Sim {
 public:
  explicit Dh3Sim(std::vector<std::string> args, Process::Stdin stdin_mode = Process::Stdin::pipe) {
    // Fast hands so the motion examples finish quickly; time is not asserted.
    std::vector<std::string> all{"--listen", "127.0.0.1:0", "--init-time-ms", "100",
                                 "--speed",  "1000",        "--log-level",    "warn"};
    all.insert(all.end(), args.begin(), args.end());
    process_ = std::make_unique<Process>(DH3_SIM_PATH, all, stdin_mode);
    if (!process_->started()) return;
    const auto line = process_->wait_for_line("listening ", kDeadline);
    if (!line) return;
    port_ = static_cast<std::uint16_t>(std::stoi(line->substr(line->rfind(':') + 1)));
  }

  [[nodiscard]] std::uint16_t port() const { return port_; }
  Process& process() { return *process_; }

  std::unique_ptr<RawTcpClient> connect() { return std::make_unique<RawTcpClient>(port_); }

  /// Sends a control command on stdin and returns its answer line.
  std::string control(const std::string& command) {
    process_->write_line(command);
    return process_->read_line(kDeadline).value_or("<no answer>");
  }

 private:
  std::unique_ptr<Process> process_;
  std::uint16_t port_ = 0;
};

class Dh3SimTest : public ::testing::Test {
 protected:
  void start(std::vector<std::string> args = {"--hands", "1"},
             Process::Stdin stdin_mode = Process::Stdin::pipe) {
    sim_ = std::make_unique<Dh3Sim>(std::move(args), stdin_mode);
    ASSERT_NE(sim_->port(), 0) << "dh3-sim did not print its port";
    box_ = sim_->connect();
    ASSERT_TRUE(box_->connected());
  }

  /// Sends one frame and returns the next 14 bytes received, as hex.
  std::string exchange(std::string_view frame) {
    EXPECT_TRUE(box_->send_hex(frame));
    return box_->read_hex(kFrame, kDeadline);
  }

  /// Asks `request` every 10 ms until the reply is `wanted` (within the deadline).
  bool poll_until(std::string_view request, std::string_view wanted) {
    const auto deadline = std::chrono::steady_clock::now() + kDeadline;
    while (std::chrono::steady_clock::now() < deadline) {
      if (exchange(request) == wanted) return true;
      std::this_thread::sleep_for(10ms);  // command pacing, not a wait for time
    }
    return false;
  }

  void initialize() {
    ASSERT_EQ(exchange("FF FE FD FC 01 08 02 01 00 00 00 00 00 FB"),
              "FF FE FD FC 01 08 02 01 00 00 00 00 00 FB");
    ASSERT_TRUE(poll_until("FF FE FD FC 01 08 02 00 00 00 00 00 00 FB",
                           "FF FE FD FC 01 08 02 00 00 01 00 00 00 FB"));
  }

  std::unique_ptr<Dh3Sim> sim_;
  std::unique_ptr<RawTcpClient> box_;
};

// -------------------------------------------------------- Initialization (0x08)

TEST_F(Dh3SimTest, InitializationSequenceWithFeedbackAsInTheDocument) {
  start();
  // Read whether feedback is enabled: not yet ("no").
  EXPECT_EQ(exchange("FF FE FD FC 01 08 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 08 01 00 00 00 00 00 00 FB");
  // Read whether initialization finished: a fresh hand has not ("not finished").
  EXPECT_EQ(exchange("FF FE FD FC 01 08 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 08 02 00 00 00 00 00 00 FB");
  // Set initialization feedback.
  EXPECT_EQ(exchange("FF FE FD FC 01 08 01 01 00 00 00 00 00 FB"),
            "FF FE FD FC 01 08 01 01 00 A5 00 00 00 FB");
  // Read whether feedback is enabled: "yes".
  EXPECT_EQ(exchange("FF FE FD FC 01 08 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 08 01 00 00 A5 00 00 00 FB");
  // Initialize (also the document's "Example, initialization").
  EXPECT_EQ(exchange("FF FE FD FC 01 08 02 01 00 00 00 00 00 FB"),
            "FF FE FD FC 01 08 02 01 00 00 00 00 00 FB");
  // Later and unsolicited, nothing asked in between.
  EXPECT_EQ(box_->read_hex(kFrame, kDeadline), "FF FE FD FC 01 08 02 00 00 00 00 00 00 FB");
  // Read whether initialization finished: "finished".
  EXPECT_EQ(exchange("FF FE FD FC 01 08 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 08 02 00 00 01 00 00 00 FB");
}

// -------------------------------------------------------- Force (0x05)

TEST_F(Dh3SimTest, ForceSetAndReadAsInTheDocument) {
  start();
  EXPECT_EQ(exchange("FF FE FD FC 01 05 02 01 00 1E 00 00 00 FB"),
            "FF FE FD FC 01 05 02 01 00 1E 00 00 00 FB");
  EXPECT_EQ(exchange("FF FE FD FC 01 05 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 05 02 00 00 1E 00 00 00 FB");
}

// -------------------------------------------------------- Position (0x06) and grip status

TEST_F(Dh3SimTest, PositionSetAndReadAsInTheDocument) {
  start();
  initialize();
  // Read current status before any motion: "default".
  EXPECT_EQ(exchange("FF FE FD FC 01 0F 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 0F 01 00 00 00 00 00 00 FB");
  EXPECT_EQ(exchange("FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB"),
            "FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB");
  // "Arrived at position", in the data-field form (see the top of this file).
  ASSERT_TRUE(poll_until("FF FE FD FC 01 0F 01 00 00 00 00 00 00 FB",
                         "FF FE FD FC 01 0F 01 00 00 02 00 00 00 FB"));
  EXPECT_EQ(exchange("FF FE FD FC 01 06 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 06 02 00 00 3C 00 00 00 FB");
}

TEST_F(Dh3SimTest, GripStatusCaughtTheObject) {
  start({"--hands", "1", "--object", "1:80"});
  initialize();
  EXPECT_EQ(exchange("FF FE FD FC 01 06 02 01 00 14 00 00 00 FB"),
            "FF FE FD FC 01 06 02 01 00 14 00 00 00 FB");
  // "Caught the object", data-field form.
  ASSERT_TRUE(poll_until("FF FE FD FC 01 0F 01 00 00 00 00 00 00 FB",
                         "FF FE FD FC 01 0F 01 00 00 03 00 00 00 FB"));
  EXPECT_EQ(exchange("FF FE FD FC 01 06 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 06 02 00 00 50 00 00 00 FB")
      << "the fingers stopped at the object (80 %)";
}

TEST_F(Dh3SimTest, ADropLetsTheFingersCloseWithoutACommand) {
  start({"--hands", "1", "--object", "1:80"});
  initialize();
  exchange("FF FE FD FC 01 06 02 01 00 14 00 00 00 FB");
  ASSERT_TRUE(poll_until("FF FE FD FC 01 0F 01 00 00 00 00 00 00 FB",
                         "FF FE FD FC 01 0F 01 00 00 03 00 00 00 FB"));
  EXPECT_EQ(sim_->control("drop 1"), "ok drop 1");
  ASSERT_TRUE(poll_until("FF FE FD FC 01 0F 01 00 00 00 00 00 00 FB",
                         "FF FE FD FC 01 0F 01 00 00 02 00 00 00 FB"));
  EXPECT_EQ(exchange("FF FE FD FC 01 06 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 06 02 00 00 14 00 00 00 FB");
}

// -------------------------------------------------------- Rotation (0x07) and its status

TEST_F(Dh3SimTest, RotationSetAndReadAsInTheDocument) {
  start();
  initialize();
  // Read current rotation status before any rotation: "default".
  EXPECT_EQ(exchange("FF FE FD FC 01 0F 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 0F 02 00 00 00 00 00 00 FB");
  EXPECT_EQ(exchange("FF FE FD FC 01 07 02 01 00 43 00 00 00 FB"),
            "FF FE FD FC 01 07 02 01 00 43 00 00 00 FB");
  // "Arrived at rotation", data-field form.
  ASSERT_TRUE(poll_until("FF FE FD FC 01 0F 02 00 00 00 00 00 00 FB",
                         "FF FE FD FC 01 0F 02 00 00 02 00 00 00 FB"));
  EXPECT_EQ(exchange("FF FE FD FC 01 07 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 07 02 00 00 43 00 00 00 FB");
}

TEST_F(Dh3SimTest, RotationStatusBlockedByAnObstacle) {
  start({"--hands", "1", "--obstacle", "1:40"});
  initialize();
  exchange("FF FE FD FC 01 07 02 01 00 43 00 00 00 FB");
  // The document's "caught the object" for rotation, data-field form.
  ASSERT_TRUE(poll_until("FF FE FD FC 01 0F 02 00 00 00 00 00 00 FB",
                         "FF FE FD FC 01 0F 02 00 00 03 00 00 00 FB"));
  EXPECT_EQ(exchange("FF FE FD FC 01 07 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 07 02 00 00 28 00 00 00 FB");
}

// -------------------------------------------------------- CAN ID (0x12)

TEST_F(Dh3SimTest, CanIdExamplesAsInTheDocument) {
  start();
  // Set ID to 2 when the ID is 1.
  EXPECT_EQ(exchange("FF FE FD FC 01 12 01 01 00 02 00 00 00 FB"),
            "FF FE FD FC 01 12 01 01 00 02 00 00 00 FB");
  // Set ID to 2 with ID 0.
  EXPECT_EQ(exchange("FF FE FD FC 00 12 01 01 00 02 00 00 00 FB"),
            "FF FE FD FC 00 12 01 01 00 02 00 00 00 FB");
  // Read ID with ID 0, as printed (write flag, data 0): answers the ID, 2.
  EXPECT_EQ(exchange("FF FE FD FC 00 12 01 01 00 00 00 00 00 FB"),
            "FF FE FD FC 00 12 01 01 00 02 00 00 00 FB");
  // The new ID takes effect after a reboot.
  EXPECT_EQ(sim_->control("reboot 1"), "ok reboot 1 (now ID 2)");
  // Read ID when ID = 2.
  EXPECT_EQ(exchange("FF FE FD FC 02 12 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 02 12 01 00 00 02 00 00 00 FB");
}

// -------------------------------------------------------- Version (0x13), baud (0x14)

TEST_F(Dh3SimTest, FirmwareVersionAsInTheDocument) {
  start();
  EXPECT_EQ(exchange("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
}

TEST_F(Dh3SimTest, BaudRateSetAndReadAsInTheDocument) {
  start();
  EXPECT_EQ(exchange("FF FE FD FC 01 14 01 01 00 02 00 00 00 FB"),
            "FF FE FD FC 01 14 01 01 00 02 00 00 00 FB");
  EXPECT_EQ(exchange("FF FE FD FC 01 14 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 14 01 00 00 02 00 00 00 FB");
}

// -------------------------------------------------------- the box itself

TEST_F(Dh3SimTest, SeveralHandsAnswerOnTheirOwnIds) {
  start({"--hands", "1,3"});
  EXPECT_EQ(exchange("FF FE FD FC 03 05 02 01 00 1E 00 00 00 FB"),
            "FF FE FD FC 03 05 02 01 00 1E 00 00 00 FB");
  EXPECT_EQ(exchange("FF FE FD FC 01 05 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 05 02 00 00 32 00 00 00 FB")
      << "hand 1 kept its own force (50)";
  // Nobody is 2: the next frame received is the answer to the request after it.
  box_->send_hex("FF FE FD FC 02 13 01 00 00 00 00 00 00 FB");
  EXPECT_EQ(exchange("FF FE FD FC 03 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 03 13 01 00 00 00 02 01 04 FB");
}

TEST_F(Dh3SimTest, RepliesGoToTheAskerAndUnsolicitedFramesToEveryone) {
  start();
  auto other = sim_->connect();
  ASSERT_TRUE(other->connected());
  // An answer shows the sim has accepted the other connection.
  other->send_hex("FF FE FD FC 01 05 03 00 00 00 00 00 00 FB");
  ASSERT_EQ(other->read_hex(kFrame, kDeadline), "FF FE FD FC 01 05 03 00 00 32 00 00 00 FB");
  EXPECT_EQ(exchange("FF FE FD FC 01 08 01 01 00 00 00 00 00 FB"),
            "FF FE FD FC 01 08 01 01 00 A5 00 00 00 FB");
  EXPECT_EQ(exchange("FF FE FD FC 01 08 02 01 00 00 00 00 00 FB"),
            "FF FE FD FC 01 08 02 01 00 00 00 00 00 FB");
  // The other client asked nothing: the first thing it gets is the unsolicited frame.
  EXPECT_EQ(other->read_hex(kFrame, kDeadline), "FF FE FD FC 01 08 02 00 00 00 00 00 00 FB");
  EXPECT_EQ(box_->read_hex(kFrame, kDeadline), "FF FE FD FC 01 08 02 00 00 00 00 00 00 FB");
  // And the asker's replies never reach the other client.
  EXPECT_EQ(exchange("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
  other->send_hex("FF FE FD FC 01 05 02 00 00 00 00 00 00 FB");
  EXPECT_EQ(other->read_hex(kFrame, kDeadline), "FF FE FD FC 01 05 02 00 00 32 00 00 00 FB");
}

TEST_F(Dh3SimTest, GarbageAndSplitFramesAreHandled) {
  start();
  // Junk, a lone end byte, a truncated header, then a frame sent in two pieces.
  ASSERT_TRUE(box_->send_hex("00 13 FB FF FE FD FF FE FD FC 01 13 01"));
  ASSERT_TRUE(box_->send_hex("00 00 00 00 00 00 FB"));
  EXPECT_EQ(box_->read_hex(kFrame, kDeadline), "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
  // Two frames in one write: two replies, in order.
  ASSERT_TRUE(
      box_->send_hex("FF FE FD FC 01 05 02 01 00 1E 00 00 00 FB "
                     "FF FE FD FC 01 05 03 01 00 28 00 00 00 FB"));
  EXPECT_EQ(box_->read_hex(kFrame, kDeadline), "FF FE FD FC 01 05 02 01 00 1E 00 00 00 FB");
  EXPECT_EQ(box_->read_hex(kFrame, kDeadline), "FF FE FD FC 01 05 03 01 00 28 00 00 00 FB");
}

TEST_F(Dh3SimTest, MutedHandsAreSilentUntilUnmuted) {
  start({"--hands", "1,2"});
  EXPECT_EQ(sim_->control("mute 1"), "ok mute 1");
  box_->send_hex("FF FE FD FC 01 05 02 01 00 1E 00 00 00 FB");  // lost
  // Hand 2's answer proves the sim has read the frame to hand 1 (TCP keeps
  // the order) before hand 1 is unmuted; and it is the first frame to arrive.
  EXPECT_EQ(exchange("FF FE FD FC 02 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 02 13 01 00 00 00 02 01 04 FB");
  EXPECT_EQ(sim_->control("unmute 1"), "ok unmute 1");
  // The muted write was not applied either: the force is still 50.
  EXPECT_EQ(exchange("FF FE FD FC 01 05 02 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 05 02 00 00 32 00 00 00 FB");
}

TEST_F(Dh3SimTest, CorruptionFlipsTheLowDataByte) {
  start();
  EXPECT_EQ(sim_->control("corrupt 1 1"), "ok corrupt 1 1");
  EXPECT_EQ(exchange("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 13 01 00 00 FF 02 01 04 FB");
  EXPECT_EQ(exchange("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
}

TEST_F(Dh3SimTest, ADelayedHandStillAnswers) {
  start();
  EXPECT_EQ(sim_->control("delay 1 50"), "ok delay 1 50");
  EXPECT_EQ(exchange("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
}

TEST_F(Dh3SimTest, KickClosesEveryConnectionAndNewOnesWork) {
  start();
  // An answer shows the sim has accepted the connection.
  EXPECT_EQ(exchange("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
  EXPECT_EQ(sim_->control("kick"), "ok kick 1");
  EXPECT_TRUE(box_->wait_closed(kDeadline));
  box_ = sim_->connect();
  ASSERT_TRUE(box_->connected());
  EXPECT_EQ(exchange("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
}

TEST_F(Dh3SimTest, ControlErrorsAreAnswered) {
  start();
  EXPECT_EQ(sim_->control("mute 7"), "error no hand 7");
  EXPECT_EQ(sim_->control("object 1 101"), "error position must be 0-100 or none");
  EXPECT_TRUE(sim_->control("fly 1").starts_with("error unknown command"));
  EXPECT_EQ(sim_->control("hands"), "ok hands 1");
}

TEST_F(Dh3SimTest, SigtermStopsItCleanly) {
  start();
  ASSERT_TRUE(sim_->process().send_signal(SIGTERM));
  const auto status = sim_->process().wait_exit(kDeadline);
  ASSERT_TRUE(status.has_value()) << "dh3-sim did not stop";
  EXPECT_TRUE(WIFEXITED(*status));
  EXPECT_EQ(WEXITSTATUS(*status), 0);
  EXPECT_TRUE(box_->wait_closed(kDeadline));
}

TEST_F(Dh3SimTest, QuitStopsIt) {
  start();
  EXPECT_EQ(sim_->control("quit"), "ok quit");
  const auto status = sim_->process().wait_exit(kDeadline);
  ASSERT_TRUE(status.has_value()) << "dh3-sim did not stop";
  EXPECT_TRUE(WIFEXITED(*status));
  EXPECT_EQ(WEXITSTATUS(*status), 0);
}

TEST_F(Dh3SimTest, TheEndOfStdinDoesNotStopItButSigintDoes) {
  // Stdin at end of file from the start: dh3-sim sees it in its first round,
  // before it can read anything from a client it accepts in that round.
  start({"--hands", "1"}, Process::Stdin::dev_null);
  EXPECT_EQ(exchange("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
  ASSERT_TRUE(sim_->process().send_signal(SIGINT));
  const auto status = sim_->process().wait_exit(kDeadline);
  ASSERT_TRUE(status.has_value()) << "dh3-sim did not stop";
  EXPECT_TRUE(WIFEXITED(*status));
  EXPECT_EQ(WEXITSTATUS(*status), 0);
}

// -------------------------------------------------------- --min-interval-ms (TCP)

TEST_F(Dh3SimTest, FramesCloserThanTheMinimumIntervalAreCountedAndReportedAtExit) {
  start({"--hands", "1,2", "--min-interval-ms", "20"});
  EXPECT_EQ(sim_->control("violations"), "ok 0");
  // Two frames to hand 1 in one write are read together: 0 ms apart.
  ASSERT_TRUE(
      box_->send_hex("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB "
                     "FF FE FD FC 01 05 02 00 00 00 00 00 00 FB"));
  EXPECT_EQ(box_->read_hex(kFrame, kDeadline), "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
  EXPECT_EQ(box_->read_hex(kFrame, kDeadline), "FF FE FD FC 01 05 02 00 00 32 00 00 00 FB");
  EXPECT_EQ(sim_->control("violations"), "ok 1");
  // Hand 2 has its own interval: its first frame is no violation.
  EXPECT_EQ(exchange("FF FE FD FC 02 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 02 13 01 00 00 00 02 01 04 FB");
  // Further apart than the minimum: the sim read the last frame to hand 1
  // before it answered, and the next one is sent 50 ms after that answer.
  std::this_thread::sleep_for(50ms);  // the spacing under test, not a wait for an event
  EXPECT_EQ(exchange("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
  EXPECT_EQ(sim_->control("violations"), "ok 1");
  EXPECT_EQ(sim_->control("quit"), "ok quit");
  EXPECT_EQ(sim_->process().read_line(kDeadline), "interval violations: 1");
  const auto status = sim_->process().wait_exit(kDeadline);
  ASSERT_TRUE(status.has_value()) << "dh3-sim did not stop";
  EXPECT_EQ(WEXITSTATUS(*status), 0);
  EXPECT_EQ(sim_->process().read_line(kDeadline), std::nullopt) << "nothing after the last line";
}

TEST_F(Dh3SimTest, TheIntervalLineIsPrintedAlsoForZeroAndOnSigterm) {
  start({"--hands", "1", "--min-interval-ms", "20"});
  EXPECT_EQ(exchange("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB"),
            "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
  ASSERT_TRUE(sim_->process().send_signal(SIGTERM));
  EXPECT_EQ(sim_->process().read_line(kDeadline), "interval violations: 0");
  const auto status = sim_->process().wait_exit(kDeadline);
  ASSERT_TRUE(status.has_value()) << "dh3-sim did not stop";
  EXPECT_EQ(WEXITSTATUS(*status), 0);
}

TEST_F(Dh3SimTest, WithoutAMinimumIntervalNothingIsCounted) {
  start();
  EXPECT_EQ(sim_->control("violations"),
            "error the interval check is off (start with --min-interval-ms)");
  EXPECT_EQ(sim_->control("quit"), "ok quit");
  EXPECT_EQ(sim_->process().read_line(kDeadline), std::nullopt) << "no interval line";
}

TEST(Dh3SimCommandLine, BadArgumentsAreRefusedWithAnError) {
  Process sim(DH3_SIM_PATH, {"--hands", "0"});
  ASSERT_TRUE(sim.started());
  const auto status = sim.wait_exit(kDeadline);
  ASSERT_TRUE(status.has_value());
  EXPECT_NE(WEXITSTATUS(*status), 0);
}

TEST(Dh3SimCommandLine, CanAndListenExcludeEachOther) {
  Process sim(DH3_SIM_PATH, {"--can", "vcan0", "--listen", "127.0.0.1:0"});
  const auto status = sim.wait_exit(kDeadline);
  ASSERT_TRUE(status.has_value());
  EXPECT_NE(WEXITSTATUS(*status), 0);
}

TEST(Dh3SimCommandLine, AnInterfaceThatCannotServeIsRefused) {
  // Without kernel CAN: "kernel has no CAN support"; with it: no such interface.
  Process sim(DH3_SIM_PATH, {"--can", "dh3nosuchcan0", "--hands", "1"});
  const auto status = sim.wait_exit(kDeadline);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(WEXITSTATUS(*status), 1);
  EXPECT_EQ(sim.read_line(kDeadline), std::nullopt) << "no ready line";
}

TEST(Dh3SimCommandLine, APortInUseIsRefused) {
  Dh3Sim first({"--hands", "1"});
  ASSERT_NE(first.port(), 0);
  Process second(DH3_SIM_PATH, {"--listen", "127.0.0.1:" + std::to_string(first.port())});
  const auto status = second.wait_exit(kDeadline);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(WEXITSTATUS(*status), 1);
}

}  // namespace
