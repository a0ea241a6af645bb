// dh3-service --metrics: a real service process, driven over DDS, scraped over
// HTTP on loopback as Prometheus would scrape it. The port is 0 (the kernel
// picks a free one, so parallel tests never clash) and read from the log line
// the service writes.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "service_fixture.hpp"
#include "support/metrics_scrape.hpp"

namespace dh3::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr const char* kConfig = R"(
metrics: 192.0.2.1:9    # the command line's --metrics wins over this
buses:
  - name: bus0
    spec: sim
    command_interval_ms: 2
    poll_interval_moving_ms: 20
    poll_interval_idle_ms: 100
    sim: {reply_delay_ms: 1, init_time_ms: 100}
    hands:
      - {id: 1, name: left}
      - {id: 2}
  - name: line
    spec: sim
    poll_interval_idle_ms: 100
    sim: {bit_rate: 125000}
    hands:
      - {id: 5}
)";

std::string series(const std::string& name, const std::string& labels) {
  return name + "{" + labels + "}";
}

TEST(ServiceMetrics, CountsWhatTheServiceDidAndServesItOnTheLoggedPort) {
  TempFile config(kConfig);
  MetricsService service(config.path());
  ASSERT_NE(service.port(), 0) << "dh3-service did not log where it serves metrics";
  auto client = connected_client(service.name());
  ASSERT_TRUE(client);

  const auto hand = [&](std::uint16_t id) {
    return DdsTestClient::hand(service.name(), "bus0", id);
  };
  const auto code = [&](std::uint16_t id, msg::CommandType command, std::int32_t value = 0) {
    auto reply = client->call(hand(id), command, value);
    return reply ? reply->code() : msg::FAILED;
  };
  ASSERT_TRUE(client->wait_status(hand(1), [](const auto& s) { return s.online(); }));
  EXPECT_EQ(code(2, msg::MOVE, 30), msg::NOT_INITIALIZED);
  EXPECT_EQ(code(1, msg::INITIALIZE), msg::OK);
  EXPECT_EQ(code(1, msg::MOVE, 50), msg::OK);
  EXPECT_EQ(code(1, msg::MOVE, 70), msg::OK);
  EXPECT_EQ(code(1, msg::SET_CLOSING_FORCE, 40), msg::OK);
  EXPECT_EQ(code(9, msg::MOVE, 50), msg::UNKNOWN_HAND);  // refused before any hand

  const std::string left = R"(bus="bus0",hand="1",name="left")";
  const std::string right = R"(bus="bus0",hand="2",name="")";
  const std::string moves_ok =
      series("dh3_hand_commands_total", left + R"(,type="MOVE",result="OK")");
  // The line bus's load needs a whole second of traffic behind it.
  const std::string text = scrape_until(service.port(), [&](const std::string& t) {
    const auto load = metric_value(t, R"(dh3_bus_load_percent{bus="line"})");
    return metric_value(t, moves_ok) == 2.0 && load && *load > 0.0;
  });
  EXPECT_EQ(metric_value(text, moves_ok), 2.0) << text;
  EXPECT_EQ(metric_value(text, series("dh3_hand_commands_total",
                                      left + R"(,type="INITIALIZE",result="OK")")),
            1.0);
  EXPECT_EQ(metric_value(text, series("dh3_hand_commands_total",
                                      left + R"(,type="SET_CLOSING_FORCE",result="OK")")),
            1.0);
  EXPECT_EQ(metric_value(text, series("dh3_hand_commands_total",
                                      right + R"(,type="MOVE",result="NOT_INITIALIZED")")),
            1.0);
  EXPECT_THAT(text, Not(HasSubstr(R"(hand="9")")));

  EXPECT_EQ(metric_value(text, series("dh3_hand_online", left)), 1.0);
  EXPECT_EQ(metric_value(text, series("dh3_hand_online", right)), 1.0);
  EXPECT_EQ(metric_value(text, series("dh3_hand_online", R"(bus="line",hand="5",name="")")), 1.0);
  EXPECT_GT(metric_value(text, series("dh3_hand_round_trip_seconds_count", left)).value_or(0), 0);
  EXPECT_EQ(metric_value(text, series("dh3_hand_timeouts_total", left)), 0.0);

  EXPECT_GT(metric_value(text, R"(dh3_bus_frames_sent_total{bus="bus0"})").value_or(0), 0);
  EXPECT_GT(metric_value(text, R"(dh3_bus_frames_received_total{bus="bus0"})").value_or(0), 0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_link_up{bus="bus0"})"), 1.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_reconnects_total{bus="bus0"})"), 0.0);
  // The service's own refusals: none for a client that sends one at a time.
  EXPECT_EQ(metric_value(text, R"(dh3_requests_busy_total{reason="in_flight"})"), 0.0);
  EXPECT_EQ(metric_value(text, R"(dh3_requests_busy_total{reason="rate"})"), 0.0);
  EXPECT_EQ(metric_value(text, "dh3_held_replies_dropped_total"), 0.0);
  EXPECT_EQ(metric_value(text, R"(dh3_bus_errors_total{bus="bus0",kind="unexpected_frame"})"), 0.0);
  // Only the bus that knows its bit rate has a load figure; polling one hand
  // is a few percent of 125 kbit/s, not all of it.
  EXPECT_FALSE(metric_value(text, R"(dh3_bus_load_percent{bus="bus0"})"));
  const auto load = metric_value(text, R"(dh3_bus_load_percent{bus="line"})");
  ASSERT_TRUE(load);
  EXPECT_GT(*load, 0.0);
  EXPECT_LT(*load, 50.0);

  EXPECT_EQ(service.stop(), 0);
}

/// The upper bounds the latency histograms are exported with, as written.
const std::vector<std::string> kLatencyBounds = {
    "0.0005", "0.001", "0.002", "0.005", "0.01", "0.015", "0.02", "0.025", "0.03",
    "0.04",   "0.05",  "0.06",  "0.08",  "0.1",  "0.25",  "1",    "+Inf"};

/// Checks `name`'s buckets for `labels`: every bound there, cumulative (never
/// falling), the +Inf one equal to the count; returns the count.
double checked_histogram(const std::string& text, const std::string& name,
                         const std::string& labels) {
  double previous = 0.0;
  for (const std::string& bound : kLatencyBounds) {
    const auto bucket = metric_value(text, name + "_bucket{" + labels + ",le=\"" + bound + "\"}");
    EXPECT_TRUE(bucket) << name << " has no bucket " << bound;
    if (!bucket) continue;
    EXPECT_GE(*bucket, previous) << name << " falls at " << bound;
    previous = *bucket;
  }
  EXPECT_EQ(metric_value(text, name + "_count{" + labels + "}"), previous) << name;
  EXPECT_TRUE(metric_value(text, name + "_sum{" + labels + "}")) << name;
  return previous;
}

TEST(ServiceMetrics, LatencyHistogramsCountKnownCommandsAndTheirBucketsAgree) {
  // Every reply takes the sim's 5 ms, so nothing lands at 2 ms or below.
  TempFile config(R"(
buses:
  - name: slow
    spec: sim
    poll_interval_idle_ms: 100
    sim: {reply_delay_ms: 5, init_time_ms: 100}
    hands:
      - {id: 3}
)");
  MetricsService service(config.path());
  ASSERT_NE(service.port(), 0) << "dh3-service did not log where it serves metrics";
  auto client = connected_client(service.name());
  ASSERT_TRUE(client);
  const auto hand = DdsTestClient::hand(service.name(), "slow", 3);
  const auto code = [&](msg::CommandType command, std::int32_t value = 0,
                        std::uint16_t register_code = 0) {
    auto reply = client->call(hand, command, value, register_code);
    return reply ? reply->code() : msg::FAILED;
  };
  ASSERT_TRUE(client->wait_status(hand, [](const auto& s) { return s.online(); }));
  EXPECT_EQ(code(msg::INITIALIZE), msg::OK);
  EXPECT_EQ(code(msg::MOVE, 40), msg::OK);
  EXPECT_EQ(code(msg::RELEASE, 90), msg::OK);
  EXPECT_EQ(code(msg::SET_CLOSING_FORCE, 40), msg::OK);
  EXPECT_EQ(code(msg::READ_REGISTER, 0, 0x0F01), msg::OK);
  const double commands = 5;

  const std::string bus = R"(bus="slow")";
  const std::string to_reply = "dh3_bus_command_to_reply_seconds";
  const std::string text = scrape_until(service.port(), [&](const std::string& t) {
    return metric_value(t, to_reply + "_count{" + bus + "}") == commands;
  });
  EXPECT_EQ(checked_histogram(text, to_reply, bus), commands) << text;
  EXPECT_EQ(checked_histogram(text, "dh3_bus_command_to_frame_seconds", bus), commands);
  // Every frame's reply, polls included: the same count as the hand's own histogram.
  const double frames = checked_histogram(text, "dh3_bus_frame_to_reply_seconds", bus);
  const auto hand_frames =
      metric_value(text, R"(dh3_hand_round_trip_seconds_count{bus="slow",hand="3",name=""})");
  ASSERT_TRUE(hand_frames);
  EXPECT_GE(frames, commands);
  EXPECT_NEAR(frames, *hand_frames, 2.0) << "polls go on between the two reads of one scrape";
  EXPECT_GT(checked_histogram(text, "dh3_bus_status_sample_age_seconds", bus), 0.0);
  // Nothing comes back faster than the hand answers.
  for (const std::string& name : {to_reply, std::string("dh3_bus_frame_to_reply_seconds")}) {
    EXPECT_EQ(metric_value(text, name + "_bucket{" + bus + R"(,le="0.002"})"), 0.0) << name;
  }
  EXPECT_EQ(service.stop(), 0);
}

TEST(ServiceMetrics, AnAddressItCannotServeOnEndsStartUpWithAClearMessage) {
  const std::string common = "--domain " + std::to_string(test_domain()) + " --name " +
                             test_service_name() + " --bus sim:1 ";
  const auto [malformed, malformed_output] = run_to_exit(common + "--metrics localhost:9464");
  EXPECT_EQ(malformed, 2);
  EXPECT_THAT(malformed_output, HasSubstr("--metrics: metrics address 'localhost:9464'"));

  TempFile config("metrics: 127.0.0.1:70000\nbuses: [{spec: sim}]\n");
  const auto [bad_key, key_output] = run_to_exit("--config " + config.path());
  EXPECT_EQ(bad_key, 2);
  EXPECT_THAT(key_output, HasSubstr(config.path() + ":1: metrics:"));

  // 192.0.2.1 (TEST-NET-1) is no address of this host: binding it fails.
  const auto [unbound, unbound_output] = run_to_exit(common + "--metrics 192.0.2.1:9464");
  EXPECT_EQ(unbound, 1);
  EXPECT_THAT(unbound_output, HasSubstr("cannot serve metrics on 192.0.2.1:9464"));
}

}  // namespace
}  // namespace dh3::test
