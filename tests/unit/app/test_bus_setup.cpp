#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "dh3/app/bus_setup.hpp"
#include "dh3/protocol/codec.hpp"
#include "dh3/sim/sim_bus.hpp"
#include "support/bus_wait.hpp"

namespace dh3::app {
namespace {

using ::testing::ElementsAre;

BusSettings bus(std::string spec, std::vector<HandSettings> hands = {}) {
  BusSettings settings;
  // Not a one-character literal: GCC 12 at -O3 warns falsely about assigning
  // one (-Wrestrict inside libstdc++'s string replace, GCC bug 105329).
  settings.name = "bus";
  settings.spec = std::move(spec);
  settings.hands = std::move(hands);
  return settings;
}

TEST(BusSetup, BareSimSimulatesTheListedHands) {
  EXPECT_THAT(simulated_ids(bus("sim", {{4, "", {}, {}}, {9, "", {}, {}}})), ElementsAre(4, 9));
  EXPECT_THAT(simulated_ids(bus("sim")), ElementsAre(1));
  EXPECT_THAT(simulated_ids(bus("sim:2,3", {{4, "", {}, {}}})), ElementsAre(2, 3));
}

TEST(BusSetup, ExpectedHandsComeFromTheListOrTheSimulator) {
  const auto listed = expected_hands(bus("tcp:127.0.0.1:9", {{7, "left", {}, {}}}));
  ASSERT_EQ(listed.size(), 1U);
  EXPECT_EQ(listed[0].can_id, 7);
  EXPECT_EQ(listed[0].name, "left");
  const auto simulated = expected_hands(bus("sim:1,2"));
  ASSERT_EQ(simulated.size(), 2U);
  EXPECT_EQ(simulated[1].can_id, 2);
  // A real bus without a list: the scheduler discovers the hands.
  EXPECT_TRUE(expected_hands(bus("tcp:127.0.0.1:9")).empty());
}

TEST(BusSetup, OpensSimBusesWithTheirHands) {
  ServiceConfig config;
  config.allow_admin = true;
  config.buses.push_back(bus("sim", {{3, "x", 40, {}}}));
  auto setups = open_buses(config, SystemClock::instance());
  ASSERT_TRUE(setups.ok()) << setups.error();
  ASSERT_EQ(setups->size(), 1U);
  EXPECT_EQ((*setups)[0].bus->spec(), "sim:3");
  EXPECT_TRUE((*setups)[0].scheduler.allow_admin);
  ASSERT_EQ((*setups)[0].hands.size(), 1U);
  EXPECT_EQ((*setups)[0].hands[0].name, "x");
}

TEST(BusSetup, ASimSpecSimulatesThoseIdsOnly) {
  ServiceConfig config;
  config.buses.push_back(bus("sim:2,5"));
  auto setups = open_buses(config, SystemClock::instance());
  ASSERT_TRUE(setups.ok()) << setups.error();
  bus::Bus& opened = *(*setups)[0].bus;
  EXPECT_EQ(opened.spec(), "sim:2,5");
  EXPECT_NE(dynamic_cast<sim::SimBus*>(&opened), nullptr);

  // Hands 2 and 5 answer a position read; hand 1 (not listed) does not.
  for (const std::uint8_t id : {1, 2, 5}) {
    ASSERT_TRUE(
        opened.send(test::to_can_frame(protocol::make_read(id, protocol::reg::kPosition))).ok());
  }
  const auto frames = test::receive_frames(opened, 2);
  ASSERT_EQ(frames.size(), 2u);
  std::vector<std::uint32_t> ids{frames[0].id, frames[1].id};
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(ids, (std::vector<std::uint32_t>{2, 5}));
}

TEST(BusSetup, UnreachableBoxStillOpensAndRetries) {
  ServiceConfig config;
  // Port 9 on loopback: nothing listens; the bus comes up as link-down.
  config.buses.push_back(bus("tcp:127.0.0.1:9"));
  auto setups = open_buses(config, SystemClock::instance());
  ASSERT_TRUE(setups.ok()) << setups.error();
  EXPECT_EQ((*setups)[0].bus->spec(), "tcp:127.0.0.1:9");
  EXPECT_EQ((*setups)[0].bus->bit_rate(), 0U);  // unknown unless configured
}

TEST(BusSetup, ABoxBusKnowsTheBitRateItWasGiven) {
  ServiceConfig config;
  config.buses.push_back(bus("tcp:127.0.0.1:9"));
  config.buses[0].bit_rate = 500'000;
  auto setups = open_buses(config, SystemClock::instance());
  ASSERT_TRUE(setups.ok()) << setups.error();
  EXPECT_EQ((*setups)[0].bus->bit_rate(), 500'000U);  // what the load figure divides by
}

TEST(BusSetup, ATransferBoxKeepsAMarginOnTheCommandIntervalAndTheOthersNone) {
  using std::chrono::milliseconds;
  ServiceConfig config;
  config.buses.push_back(bus("tcp:127.0.0.1:9"));
  config.buses.push_back(bus("sim:1"));
  config.buses.push_back(bus("tcp:127.0.0.1:9"));
  config.buses[2].interval_margin = milliseconds(0);  // the file's word wins
  auto setups = open_buses(config, SystemClock::instance());
  ASSERT_TRUE(setups.ok()) << setups.error();
  EXPECT_EQ((*setups)[0].scheduler.interval_margin, milliseconds(2));
  EXPECT_EQ((*setups)[0].scheduler.frame_spacing(), milliseconds(22));
  EXPECT_EQ((*setups)[1].scheduler.interval_margin, Duration::zero());
  EXPECT_EQ((*setups)[2].scheduler.interval_margin, Duration::zero());
  EXPECT_EQ(default_interval_margin("serial:/dev/ttyUSB0@115200"), milliseconds(2));
  EXPECT_EQ(default_interval_margin("socketcan:can0"), Duration::zero());
}

TEST(BusSetup, ARecordedBusWritesItsFramesIntoTheDirectory) {
  std::string pattern =
      (std::filesystem::temp_directory_path() / "dh3-bus-setup-XXXXXX").string();
  const std::filesystem::path dir = ::mkdtemp(pattern.data());
  ServiceConfig config;
  config.buses.push_back(bus("sim:2"));
  config.buses[0].record = bus::RecorderOptions{dir};
  {
    auto setups = open_buses(config, SystemClock::instance());
    ASSERT_TRUE(setups.ok()) << setups.error();
    bus::Bus& opened = *(*setups)[0].bus;
    ASSERT_TRUE(opened.diagnostics().recorder.has_value());
    ASSERT_TRUE(opened.send(test::to_can_frame(
        protocol::make_read(2, protocol::reg::kFirmwareVersion))));
    EXPECT_EQ(test::receive_frames(opened, 1).size(), 1U);
  }  // closing the bus writes what its recorder holds
  std::ifstream file(dir / "bus.000001.log");
  std::vector<std::string> lines;
  for (std::string line; std::getline(file, line);) lines.push_back(line);
  std::filesystem::remove_all(dir);
  ASSERT_EQ(lines.size(), 2U);
  EXPECT_TRUE(lines[0].ends_with(" bus 002#1301000000000000 T")) << lines[0];
  EXPECT_TRUE(lines[1].ends_with(" R")) << lines[1];
}

TEST(BusSetup, ARecorderThatCannotWriteStopsTheStartNamingTheBus) {
  ServiceConfig config;
  config.buses.push_back(bus("sim:2"));
  config.buses[0].record = bus::RecorderOptions{"/proc/dh3-no-such-dir"};
  auto setups = open_buses(config, SystemClock::instance());
  ASSERT_FALSE(setups.ok());
  EXPECT_THAT(setups.error(), ::testing::HasSubstr("bus 'bus': flight recorder"));
}

}  // namespace
}  // namespace dh3::app
