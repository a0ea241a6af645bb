// The exporter's text as Prometheus reads it, its names against the
// contract's, and its endpoint on loopback.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <string>

#include "conversions.hpp"
#include "dh3/contract/names.hpp"
#include "dh3/metrics/metrics_exporter.hpp"
#include "hand_directory.hpp"
#include "request_validation.hpp"
#include "support/metrics_scrape.hpp"

namespace dh3::metrics {
namespace {

using test::metric_value;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::Not;

/// One bus "left" at 500 kbit/s with hand 1 "gripper" (online, some traffic)
/// and hand 2 (offline, nothing counted).
std::vector<hand::BusMetrics> sample_figures() {
  hand::BusMetrics bus;
  bus.bus = "left";
  bus.link_up = true;
  bus.counters.frames_sent = 120;
  bus.counters.frames_received = 118;
  bus.counters.unexpected_frames = 2;
  bus.counters.bus_errors = 1;
  bus.counters.reconnects = 3;
  bus.bit_rate = 500'000;
  bus.recent_frames_per_second = 1000.0;
  bus.line_load_percent = 22.2;

  hand::HandMetrics gripper;
  gripper.can_id = 1;
  gripper.name = "gripper";
  gripper.online = true;
  gripper.commands.push_back({hand::CommandKind::move_to, {}, std::nullopt, 5});
  gripper.commands.push_back({hand::CommandKind::move_to, {}, hand::CommandError::timeout, 1});
  gripper.commands.push_back(
      {hand::CommandKind::write_register, protocol::reg::kCanId, std::nullopt, 1});
  gripper.timeouts = 4;
  gripper.retries = 2;
  gripper.round_trip.counts[1] = 3;      // <= 1 ms
  gripper.round_trip.counts[4] = 1;      // <= 10 ms
  gripper.round_trip.counts.back() = 1;  // above the largest bound
  gripper.round_trip.sum_seconds = 2.5;

  hand::HandMetrics idle;
  idle.can_id = 2;
  idle.online = false;
  bus.hands = {gripper, idle};
  return {bus};
}

TEST(MetricsText, HandSeriesCarryBusCanIdNameTypeAndResult) {
  const std::string text = render(sample_figures());
  const std::string hand1 = R"(bus="left",hand="1",name="gripper")";
  EXPECT_EQ(metric_value(text, "dh3_hand_commands_total{" + hand1 + R"(,type="MOVE",result="OK"})"),
            5.0)
      << text;
  EXPECT_EQ(
      metric_value(text, "dh3_hand_commands_total{" + hand1 + R"(,type="MOVE",result="TIMEOUT"})"),
      1.0);
  EXPECT_EQ(
      metric_value(text, "dh3_hand_commands_total{" + hand1 + R"(,type="SET_CAN_ID",result="OK"})"),
      1.0);
  EXPECT_EQ(metric_value(text, "dh3_hand_timeouts_total{" + hand1 + "}"), 4.0);
  EXPECT_EQ(metric_value(text, "dh3_hand_retries_total{" + hand1 + "}"), 2.0);
  EXPECT_EQ(metric_value(text, "dh3_hand_online{" + hand1 + "}"), 1.0);
  EXPECT_EQ(metric_value(text, R"(dh3_hand_online{bus="left",hand="2",name=""})"), 0.0);
  EXPECT_THAT(text, HasSubstr("# TYPE dh3_hand_commands_total counter"));
  EXPECT_THAT(text, HasSubstr("# TYPE dh3_hand_online gauge"));
  // Nothing counted for hand 2: no command series of its own.
  EXPECT_THAT(text, Not(HasSubstr(R"(dh3_hand_commands_total{bus="left",hand="2")")));
}

TEST(MetricsText, RoundTripIsACumulativeHistogramInSeconds) {
  const std::string text = render(sample_figures());
  const std::string series =
      R"(dh3_hand_round_trip_seconds_bucket{bus="left",hand="1",name="gripper",le=)";
  EXPECT_THAT(text, HasSubstr("# TYPE dh3_hand_round_trip_seconds histogram"));
  EXPECT_EQ(metric_value(text, series + R"("0.0005"})"), 0.0) << text;
  EXPECT_EQ(metric_value(text, series + R"("0.001"})"), 3.0);
  EXPECT_EQ(metric_value(text, series + R"("0.005"})"), 3.0);
  EXPECT_EQ(metric_value(text, series + R"("0.01"})"), 4.0);
  EXPECT_EQ(metric_value(text, series + R"("1"})"), 4.0);
  EXPECT_EQ(metric_value(text, series + R"("+Inf"})"), 5.0);
  EXPECT_EQ(metric_value(
                text, R"(dh3_hand_round_trip_seconds_count{bus="left",hand="1",name="gripper"})"),
            5.0);
  EXPECT_EQ(
      metric_value(text, R"(dh3_hand_round_trip_seconds_sum{bus="left",hand="1",name="gripper"})"),
      2.5);
}

TEST(MetricsText, BusSeriesCountFramesErrorsReconnectsAndLoad) {
  const std::string text = render(sample_figures());
  EXPECT_EQ(metric_value(text, R"(dh3_bus_frames_sent_total{bus="left"})"), 120.0) << text;
  EXPECT_EQ(metric_value(text, R"(dh3_bus_frames_received_total{bus="left"})"), 118.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_errors_total{bus="left",kind="unexpected_frame"})"), 2.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_errors_total{bus="left",kind="bus_error"})"), 1.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_reconnects_total{bus="left"})"), 3.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_link_up{bus="left"})"), 1.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_load_percent{bus="left"})"), 22.2);
}

TEST(MetricsText, LatencyHistogramsAreBusSeriesWithBucketsFromHalfAMillisecondToOneSecond) {
  auto figures = sample_figures();
  hand::LatencyHistogram age;
  for (const auto ms : {0, 15, 20, 21, 2000}) age.observe(std::chrono::milliseconds(ms));
  figures[0].latency.sample_age = age.snapshot();
  const std::string text = render(figures);
  const std::string bucket = R"(dh3_bus_status_sample_age_seconds_bucket{bus="left",le=)";
  EXPECT_THAT(text, HasSubstr("# TYPE dh3_bus_status_sample_age_seconds histogram"));
  EXPECT_EQ(metric_value(text, bucket + R"("0.0005"})"), 1.0) << text;
  EXPECT_EQ(metric_value(text, bucket + R"("0.015"})"), 2.0) << "a bound is in its bucket";
  EXPECT_EQ(metric_value(text, bucket + R"("0.02"})"), 3.0);
  EXPECT_EQ(metric_value(text, bucket + R"("0.025"})"), 4.0);
  EXPECT_EQ(metric_value(text, bucket + R"("1"})"), 4.0);
  EXPECT_EQ(metric_value(text, bucket + R"("+Inf"})"), 5.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_status_sample_age_seconds_count{bus="left"})"), 5.0);
  EXPECT_NEAR(*metric_value(text, R"(dh3_bus_status_sample_age_seconds_sum{bus="left"})"), 2.056,
              1e-9);
  // The others are there, empty.
  for (const char* name : {"dh3_bus_command_to_frame_seconds", "dh3_bus_frame_to_reply_seconds",
                           "dh3_bus_command_to_reply_seconds"}) {
    EXPECT_EQ(metric_value(text, std::string(name) + R"(_count{bus="left"})"), 0.0) << name;
  }
}

TEST(MetricsText, TheServicesBusyAnswersAndDroppedRepliesAreCounted) {
  const std::string text = render({}, RequestFigures{3, 5, 7});
  EXPECT_THAT(text, HasSubstr("dh3_requests_busy_total{reason=\"in_flight\"} 3"));
  EXPECT_THAT(text, HasSubstr("dh3_requests_busy_total{reason=\"rate\"} 5"));
  EXPECT_THAT(text, HasSubstr("dh3_held_replies_dropped_total 7"));
  EXPECT_THAT(render({}), Not(HasSubstr("dh3_requests_busy_total")));
}

TEST(MetricsText, ABusWithoutABitRateHasNoLoadSeries) {
  auto figures = sample_figures();
  figures[0].bit_rate = 0;
  figures[0].line_load_percent.reset();
  const std::string text = render(figures);
  EXPECT_THAT(text, Not(HasSubstr("dh3_bus_load_percent")));
  EXPECT_EQ(metric_value(text, R"(dh3_bus_frames_sent_total{bus="left"})"), 120.0);
}

TEST(MetricsText, ACanControllerBusHasErrorFrameOverflowAndBusOffSeries) {
  auto figures = sample_figures();
  auto& seen = figures[0].diagnostics;
  seen.sees_controller = true;
  seen.bus_off = true;
  seen.error_frames[static_cast<std::size_t>(bus::ErrorFrameKind::bus_off)] = 2;
  seen.error_frames[static_cast<std::size_t>(bus::ErrorFrameKind::error_passive)] = 5;
  seen.rx_overflow_drops = 17;
  seen.frames_ignored = 3;
  const std::string text = render(figures);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_error_frames_total{bus="left",kind="bus_off"})"), 2.0)
      << text;
  EXPECT_EQ(metric_value(text, R"(dh3_bus_error_frames_total{bus="left",kind="error_passive"})"),
            5.0);
  // Every kind is there from the start, so rate() works from the first error.
  EXPECT_EQ(metric_value(text, R"(dh3_bus_error_frames_total{bus="left",kind="no_ack"})"), 0.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_off{bus="left"})"), 1.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_rx_overflow_drops_total{bus="left"})"), 17.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_frames_ignored_total{bus="left"})"), 3.0);
}

TEST(MetricsText, ABusThatSeesNoControllerHasNoControllerSeries) {
  const std::string text = render(sample_figures());
  EXPECT_THAT(text, Not(HasSubstr("dh3_bus_error_frames_total")));
  EXPECT_THAT(text, Not(HasSubstr("dh3_bus_off")));
  EXPECT_THAT(text, Not(HasSubstr("dh3_bus_rx_overflow_drops_total")));
}

TEST(MetricsText, ARecordedBusHasRecorderSeries) {
  auto figures = sample_figures();
  figures[0].diagnostics.recorder = bus::RecorderFigures{1000, 7, 48000, 2, 1};
  const std::string text = render(figures);
  EXPECT_EQ(metric_value(text, R"(dh3_recorder_frames_total{bus="left"})"), 1000.0) << text;
  EXPECT_EQ(metric_value(text, R"(dh3_recorder_dropped_total{bus="left"})"), 7.0);
  EXPECT_EQ(metric_value(text, R"(dh3_recorder_bytes_total{bus="left"})"), 48000.0);
  EXPECT_EQ(metric_value(text, R"(dh3_recorder_files_total{bus="left"})"), 2.0);
  EXPECT_EQ(metric_value(text, R"(dh3_recorder_write_errors_total{bus="left"})"), 1.0);
}

TEST(MetricsText, ABusWithoutARecorderHasNoRecorderSeries) {
  EXPECT_THAT(render(sample_figures()), Not(HasSubstr("dh3_recorder_")));
}

// The names a dashboard filters on are the ones the contract gives the
// commands a client sends and the results it gets back.
TEST(MetricsNames, CommandTypesAreTheContractsNames) {
  const hand::HandRoster bus0({{1, ""}});
  dds::HandDirectory directory;
  directory.add_bus("bus0", bus0);
  const std::pair<msg::CommandType, std::int32_t> commands[] = {{msg::INITIALIZE, 0},
                                                                {msg::MOVE, 50},
                                                                {msg::SET_CLOSING_FORCE, 50},
                                                                {msg::SET_OPENING_FORCE, 50},
                                                                {msg::ROTATE, 50},
                                                                {msg::READ_REGISTER, 0},
                                                                {msg::SET_CAN_ID, 2},
                                                                {msg::SET_BAUD_RATE, 1},
                                                                {msg::ENABLE_INIT_FEEDBACK, 0},
                                                                {msg::GRASP, 50},
                                                                {msg::RELEASE, 80},
                                                                {msg::STOP, 0}};
  for (const auto& [type, value] : commands) {
    msg::CommandRequest request;
    request.client_id("0102030405060708090a0b0c");
    request.hand().service("dh3");
    request.hand().bus("bus0");
    request.hand().can_id(1);
    request.command(type);
    request.value(value);
    request.register_code(protocol::reg::kPosition.code());
    const auto valid = dds::validate_request(request, directory, /*allow_admin=*/true);
    ASSERT_TRUE(valid.ok()) << contract::command_name(type) << ": " << valid.error().message;
    EXPECT_EQ(command_type_name(valid->command.kind, valid->command.reg),
              contract::command_name(type));
  }
}

TEST(MetricsNames, ResultsAreTheContractsNames) {
  EXPECT_EQ(result_name(std::nullopt), dds::result_code_name(msg::OK));
  for (int e = 0; e <= static_cast<int>(hand::CommandError::failed); ++e) {
    const auto error = static_cast<hand::CommandError>(e);
    EXPECT_EQ(result_name(error), dds::result_code_name(dds::to_result_code(error)));
  }
}

TEST(MetricsAddress, OnlyIpLiteralsWithAPortAreAccepted) {
  EXPECT_TRUE(check_listen_address("127.0.0.1:9464").ok());
  EXPECT_TRUE(check_listen_address("0.0.0.0:0").ok());
  EXPECT_TRUE(check_listen_address("[::1]:9464").ok());
  EXPECT_THAT(check_listen_address("localhost:9464").error(), HasSubstr("IPv4"));
  EXPECT_THAT(check_listen_address("127.0.0.1").error(), HasSubstr("HOST:PORT"));
  EXPECT_THAT(check_listen_address("127.0.0.1:70000").error(), HasSubstr("0-65535"));
  EXPECT_THAT(check_listen_address("127.0.0.1:").error(), HasSubstr("0-65535"));
  EXPECT_THAT(check_listen_address("::1:9464").error(), HasSubstr("bracketed IPv6"));
}

TEST(MetricsAddress, TheErrorNamesTheAddressAndWhatIsWrongWithIt) {
  EXPECT_THAT(check_listen_address(":9464").error(),
              HasSubstr("metrics address ':9464': missing host"));
  EXPECT_THAT(check_listen_address("[::1:9464").error(),
              HasSubstr("metrics address '[::1:9464': missing ']'"));
  EXPECT_THAT(check_listen_address("[127.0.0.1]:9464").error(),
              HasSubstr("'[127.0.0.1]' is not an IP address"));
  EXPECT_THAT(check_listen_address("127.0.0.1:http").error(),
              HasSubstr("port 'http' is not a number"));
}

TEST(MetricsAddress, AnAddressBeyondLoopbackIsWarnedAbout) {
  EXPECT_THAT(exposure_warning("0.0.0.0:9464"),
              HasSubstr("metrics served on 0.0.0.0:9464, beyond this machine"));
  EXPECT_THAT(exposure_warning("[::]:9464"), HasSubstr("no token, no Host check"));
  EXPECT_THAT(exposure_warning("169.254.10.1:9464"), HasSubstr("beyond this machine"));
  EXPECT_THAT(exposure_warning("127.0.0.1:9464"), IsEmpty());
  EXPECT_THAT(exposure_warning("127.0.0.5:0"), IsEmpty());
  EXPECT_THAT(exposure_warning("[::1]:9464"), IsEmpty());
}

TEST(MetricsEndpoint, ServesTheFiguresOfEachScrapeOnTheBoundPort) {
  std::atomic<int> scrapes{0};
  auto exporter = Exporter::start("127.0.0.1:0", [&] {
    ++scrapes;
    auto figures = sample_figures();
    figures[0].counters.frames_sent = 100 + static_cast<std::uint64_t>(scrapes.load());
    return figures;
  });
  ASSERT_TRUE(exporter.ok()) << exporter.error();
  const std::string& address = (*exporter)->address();
  ASSERT_EQ(address.rfind("127.0.0.1:", 0), 0u) << address;
  const auto port = static_cast<std::uint16_t>(std::stoi(address.substr(10)));
  ASSERT_NE(port, 0);

  const auto first = test::scrape_metrics(port);
  ASSERT_TRUE(first);
  const auto second = test::scrape_metrics(port);
  ASSERT_TRUE(second);
  // Each scrape reads the figures afresh.
  const auto sent_first = metric_value(*first, R"(dh3_bus_frames_sent_total{bus="left"})");
  const auto sent_second = metric_value(*second, R"(dh3_bus_frames_sent_total{bus="left"})");
  ASSERT_TRUE(sent_first && sent_second) << *first;
  EXPECT_EQ(*sent_second, *sent_first + 1.0);

  // The port is taken: a second exporter on it fails with a message.
  auto clash = Exporter::start(address, [] { return std::vector<hand::BusMetrics>{}; });
  ASSERT_FALSE(clash.ok());
  EXPECT_THAT(clash.error(), HasSubstr("cannot serve metrics on " + address));
}

TEST(MetricsEndpoint, AMalformedAddressIsRefusedBeforeBinding) {
  auto exporter =
      Exporter::start("metrics.local:9464", [] { return std::vector<hand::BusMetrics>{}; });
  ASSERT_FALSE(exporter.ok());
  EXPECT_THAT(exporter.error(), HasSubstr("metrics.local:9464"));
}

}  // namespace
}  // namespace dh3::metrics
