// dh3-service on a real kernel's CAN (vcan) with dh3-sim's hands as nodes on
// the same interface, under the faults a cell sees: the interface taken down
// mid-move, deleted and created again, the bus flooded by another node, error
// frames from the controller (bus-off among them), and a hand that stops
// answering. Every request gets exactly one reply and nothing stays stuck; the
// operator sees the controller's trouble in the metrics. Run inside user-mode
// Linux by tests/kernel/uml-run.sh.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>

#include <csignal>
#include <optional>
#include <string>
#include <vector>

#include "integration/service/service_fixture.hpp"
#include "kernel/can_interfaces.hpp"
#include "reliability/reliability_fixture.hpp"
#include "support/metrics_scrape.hpp"

namespace dh3::test {
namespace {

using ::testing::StartsWith;

/// Stops a process (SIGSTOP) for as long as it exists, then lets it go on.
class PausedProcess {
 public:
  explicit PausedProcess(pid_t pid) : pid_(pid) { EXPECT_EQ(::kill(pid_, SIGSTOP), 0); }
  ~PausedProcess() { ::kill(pid_, SIGCONT); }
  PausedProcess(const PausedProcess&) = delete;
  PausedProcess& operator=(const PausedProcess&) = delete;

 private:
  pid_t pid_;
};

class ServiceOnCanKernel : public ::testing::Test {
 protected:
  /// dh3-sim with hands 1-3 (an object at 40 for hand 2) on the test's vcan,
  /// dh3-service on it at the document's pacing, every hand online.
  void start(std::vector<std::string> sim_args = {}) {
    DH3_REQUIRE_KERNEL_CAN();
    ASSERT_TRUE(vcan_.ready()) << vcan_.why();
    std::vector<std::string> args{"--hands",           "1,2,3", "--object",       "2:40",
                                  "--min-interval-ms", "20",    "--init-time-ms", "100"};
    args.insert(args.end(), sim_args.begin(), sim_args.end());
    sim_ = std::make_unique<SimProcess>(args, vcan_.name());
    ASSERT_TRUE(sim_->serving()) << "dh3-sim --can " << vcan_.name() << " did not start";
    config_ = std::make_unique<TempFile>(
        "buses:\n  - name: can\n    spec: socketcan:" + vcan_.name() +
        "\n    bit_rate: 500000\n    poll_interval_moving_ms: 50\n"
        "    poll_interval_idle_ms: 200\n    hands: [{id: 1}, {id: 2}, {id: 3}]\n");
    service_ = std::make_unique<MetricsService>(config_->path());
    ASSERT_NE(service_->port(), 0) << "dh3-service did not start";
    client_ = connected_client(service_->name());
    ASSERT_TRUE(client_) << "the service never answered";
    for (std::uint16_t id = 1; id <= 3; ++id) {
      ASSERT_TRUE(client_->wait_status(hand(id), [](const auto& s) { return s.online(); }))
          << "hand " << id << " never online";
    }
  }

  void TearDown() override {
    if (service_) {
      EXPECT_EQ(service_->stop(), 0) << "dh3-service did not stop cleanly";
    }
    if (sim_) {
      // Every frame to a hand kept the document's 20 ms, faults or not.
      EXPECT_EQ(sim_->control("violations"), "ok 0");
      sim_->control("quit");
    }
  }

  [[nodiscard]] msg::HandAddress hand(std::uint16_t id) const {
    return DdsTestClient::hand(service_->name(), "can", id);
  }

  void expect_ok(std::uint16_t id, msg::CommandType command, std::int32_t value = 0) {
    const auto seq = client_->send(client_->request(hand(id), command, value));
    const auto replies = expect_one_reply_each(*client_, {seq});
    ASSERT_EQ(replies.size(), 1U);
    EXPECT_EQ(replies[0].code(), msg::OK) << replies[0].message();
  }

  bool wait_all(bool online) {
    for (std::uint16_t id = 1; id <= 3; ++id) {
      if (!client_->wait_status(hand(id),
                                [online](const auto& s) { return s.online() == online; })) {
        return false;
      }
    }
    return true;
  }

  bool wait_link(bool up) {
    return client_
        ->wait_info(service_->name(),
                    [up](const msg::ServiceInfo& info) {
                      return !info.buses().empty() && info.buses()[0].link_up() == up;
                    })
        .has_value();
  }

  /// A grasp on hand 1 (nothing between its fingers) that takes seconds, in
  /// flight: its reply comes when the fingers stop. Its sequence number.
  std::uint64_t start_long_grasp() {
    const auto seq = client_->send(client_->request(hand(1), msg::GRASP, 50));
    // Its position write went out (the position is not read while it moves).
    EXPECT_TRUE(client_->wait_status(hand(1), [](const auto& s) {
      return s.grip() == msg::GRIP_MOVING && s.target_position() == 0;
    })) << "the grasp never started";
    EXPECT_EQ(client_->reply_count(seq), 0U) << "the grasp ended before the fault";
    return seq;
  }

  /// After a fault: the hands come back and work; the grasp went to BUS_DOWN.
  void expect_recovery_after(std::uint64_t interrupted) {
    for (const auto& reply : expect_one_reply_each(*client_, {interrupted})) {
      EXPECT_EQ(reply.code(), msg::BUS_DOWN) << reply.message();
      EXPECT_FALSE(reply.message().empty());
    }
    EXPECT_TRUE(wait_all(true)) << "the hands did not come back online";
    EXPECT_TRUE(wait_link(true));
    expect_ok(1, msg::MOVE, 80);
    expect_ok(2, msg::ROTATE, 30);
  }

  /// While the link is down, requests fail at once with BUS_DOWN, one reply each.
  void expect_bus_down_replies() {
    std::vector<std::uint64_t> seqs;
    for (std::uint16_t id = 1; id <= 3; ++id) {
      seqs.push_back(client_->send(client_->request(hand(id), msg::READ_REGISTER, 0, 0x0602)));
    }
    for (const auto& reply : expect_one_reply_each(*client_, seqs)) {
      EXPECT_EQ(reply.code(), msg::BUS_DOWN) << reply.message();
    }
  }

  /// The series' value once it is `want` (or the last value seen when it
  /// never became that within the deadline), so the test waits for the
  /// service to have taken in what it just did.
  std::optional<double> metric(const std::string& series, double want) {
    std::optional<double> value;
    scrape_until(service_->port(), [&](const std::string& text) {
      value = metric_value(text, series);
      return value == want;
    });
    return value;
  }

  OwnVcan vcan_{"dh3svc"};
  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<TempFile> config_;
  std::unique_ptr<MetricsService> service_;
  std::unique_ptr<DdsTestClient> client_;
};

TEST_F(ServiceOnCanKernel, TheInterfaceGoingDownMidGraspEndsItWithBusDownAndTheHandsReturn) {
  ASSERT_NO_FATAL_FAILURE(start({"--speed", "10"}));
  expect_ok(1, msg::INITIALIZE);
  expect_ok(2, msg::INITIALIZE);
  const auto grasp = start_long_grasp();

  ASSERT_TRUE(vcan_.set_up(false));
  EXPECT_TRUE(wait_link(false));
  EXPECT_TRUE(wait_all(false)) << "hands still online with the interface down";
  expect_bus_down_replies();
  ASSERT_TRUE(vcan_.set_up(true));
  expect_recovery_after(grasp);
}

TEST_F(ServiceOnCanKernel, TheInterfaceDeletedAndCreatedAgainIsFoundAgain) {
  ASSERT_NO_FATAL_FAILURE(start({"--speed", "10"}));
  expect_ok(1, msg::INITIALIZE);
  expect_ok(2, msg::INITIALIZE);
  const auto grasp = start_long_grasp();

  ASSERT_TRUE(vcan_.remove());
  EXPECT_TRUE(wait_link(false));
  EXPECT_TRUE(wait_all(false));
  expect_bus_down_replies();
  ASSERT_TRUE(vcan_.create());
  expect_recovery_after(grasp);
}

TEST_F(ServiceOnCanKernel, ABusFloodedByAnotherNodeStillAnswersEveryRequest) {
  ASSERT_NO_FATAL_FAILURE(start());
  expect_ok(1, msg::INITIALIZE);
  // Another node sends random standard frames (every id, every length) and
  // extended and remote frames, as fast as it can, all through the test.
  Process flood("/bin/sh",
                {"-c", "cangen " + vcan_.name() + " -g 0 -I r -L r -p 10 & cangen " + vcan_.name() +
                           " -g 1 -e -I r -L r -p 10 & cangen " + vcan_.name() +
                           " -g 1 -R -I r -p 10 & wait"},
                Process::Stdin::dev_null);
  std::vector<std::uint64_t> seqs;
  for (int i = 0; i < 10; ++i) {
    seqs.push_back(client_->send(client_->request(hand(1 + i % 3), msg::READ_REGISTER, 0, 0x1301)));
    seqs.push_back(client_->send(client_->request(hand(1), msg::SET_CLOSING_FORCE, 30 + i)));
  }
  seqs.push_back(client_->send(client_->request(hand(1), msg::MOVE, 40)));
  const auto replies = expect_one_reply_each(*client_, seqs);
  flood.send_signal(SIGTERM);
  Process("/bin/sh", {"-c", "pkill -x cangen"}, Process::Stdin::dev_null)
      .wait_exit(std::chrono::seconds(10));
  for (const auto& reply : replies) EXPECT_EQ(reply.code(), msg::OK) << reply.message();
  // Frames with a hand's id range but no DH-3 payload reached the hand layer
  // and were counted; the rest the kernel filter kept out.
  std::optional<double> unexpected;
  scrape_until(service_->port(), [&](const std::string& text) {
    unexpected = metric_value(text, R"(dh3_bus_errors_total{bus="can",kind="unexpected_frame"})");
    return unexpected.value_or(0.0) > 0.0;
  });
  EXPECT_GT(unexpected.value_or(0.0), 0.0);
  EXPECT_TRUE(wait_all(true));
}

TEST_F(ServiceOnCanKernel,
       ControllerErrorFramesAreCountedAndBusOffTakesTheHandsOfflineUntilRestart) {
  ASSERT_NO_FATAL_FAILURE(start({"--speed", "10"}));
  expect_ok(1, msg::INITIALIZE);
  expect_ok(2, msg::INITIALIZE);
  RawCanSocket controller(vcan_.name());
  ASSERT_TRUE(controller.valid());
  auto report = [&](std::uint32_t classes, std::uint8_t status = 0) {
    std::vector<std::uint8_t> data(CAN_ERR_DLC, 0);
    data[1] = status;
    ASSERT_TRUE(controller.send(CAN_ERR_FLAG | classes, data));
  };
  report(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_WARNING);
  report(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE);
  EXPECT_EQ(metric(R"(dh3_bus_error_frames_total{bus="can",kind="error_passive"})", 1.0), 1.0);
  EXPECT_EQ(metric(R"(dh3_bus_error_frames_total{bus="can",kind="error_warning"})", 1.0), 1.0);
  EXPECT_EQ(metric(R"(dh3_bus_off{bus="can"})", 0.0), 0.0);

  const auto grasp = start_long_grasp();
  // A bus-off controller receives nothing from the other nodes, and a frame
  // that reaches it after the report means it is back on the bus. On vcan the
  // hands would go on answering: a reply to a poll sent just before the report
  // could come in after it (seen under load). So the hands are paused for as
  // long as the controller is off the bus.
  std::optional<PausedProcess> hands_unheard;
  hands_unheard.emplace(sim_->process().pid());
  report(CAN_ERR_BUSOFF);
  EXPECT_TRUE(wait_link(false));
  EXPECT_TRUE(wait_all(false)) << "hands still online with the controller bus-off";
  EXPECT_EQ(metric(R"(dh3_bus_off{bus="can"})", 1.0), 1.0);
  expect_bus_down_replies();
  report(CAN_ERR_RESTARTED);
  hands_unheard.reset();
  expect_recovery_after(grasp);
  EXPECT_EQ(metric(R"(dh3_bus_off{bus="can"})", 0.0), 0.0);
  EXPECT_EQ(metric(R"(dh3_bus_error_frames_total{bus="can",kind="bus_off"})", 1.0), 1.0);
  EXPECT_EQ(metric(R"(dh3_bus_error_frames_total{bus="can",kind="restarted"})", 1.0), 1.0);
}

TEST_F(ServiceOnCanKernel, AHandThatStopsAnsweringTimesOutGoesOfflineAndComesBack) {
  ASSERT_NO_FATAL_FAILURE(start());
  expect_ok(1, msg::INITIALIZE);
  ASSERT_THAT(sim_->control("mute 3"), StartsWith("ok"));
  const auto seq = client_->send(client_->request(hand(3), msg::READ_REGISTER, 0, 0x0602));
  for (const auto& reply : expect_one_reply_each(*client_, {seq})) {
    EXPECT_EQ(reply.code(), msg::TIMEOUT) << reply.message();
  }
  EXPECT_TRUE(client_->wait_status(hand(3), [](const auto& s) { return !s.online(); }));
  expect_ok(1, msg::MOVE, 50);  // the others go on
  ASSERT_THAT(sim_->control("unmute 3"), StartsWith("ok"));
  EXPECT_TRUE(client_->wait_status(hand(3), [](const auto& s) { return s.online(); }));
  expect_ok(3, msg::INITIALIZE);
}

}  // namespace
}  // namespace dh3::test
