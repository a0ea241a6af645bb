// A hand the services' published lists rule out is refused at once; one that
// may still appear (service not heard yet, bus still discovering) is not.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "hand_lookup.hpp"

namespace dh3::detail {
namespace {

using ::testing::HasSubstr;

ServiceInfo service(std::string name, std::vector<BusInfo> buses) {
  ServiceInfo info;
  info.name = std::move(name);
  info.buses = std::move(buses);
  return info;
}

BusInfo bus(std::string name, std::vector<HandInfo> hands) {
  BusInfo info;
  info.name = std::move(name);
  info.hands = std::move(hands);
  return info;
}

HandSpec spec(std::string_view text) {
  auto parsed = parse_hand_spec(text);
  EXPECT_TRUE(parsed) << parsed.message();
  return *parsed;
}

const std::vector<ServiceInfo> kCell{service("dh3", {bus("bus0", {{1, "left"}, {2, ""}}),
                                                     bus("bus1", {{4, ""}})})};

TEST(HandLookup, AHandTheNamedServiceDoesNotListIsRuledOutWithWhatItLists) {
  const auto why = hand_ruled_out(spec("dh3/bus0/9"), kCell);
  ASSERT_TRUE(why);
  EXPECT_THAT(*why, HasSubstr("service 'dh3' has no hand bus0/9"));
  EXPECT_THAT(*why, HasSubstr("dh3/bus0/1 (left), dh3/bus0/2, dh3/bus1/4"));
}

TEST(HandLookup, AnUnknownBusAndShortFormsAreRuledOutToo) {
  EXPECT_TRUE(hand_ruled_out(spec("dh3/bus7/1"), kCell));
  EXPECT_TRUE(hand_ruled_out(spec("9"), kCell));
  EXPECT_TRUE(hand_ruled_out(spec("bus1/1"), kCell));
  EXPECT_TRUE(hand_ruled_out(spec("right"), kCell));
}

TEST(HandLookup, ListedHandsAreNotRuledOut) {
  EXPECT_FALSE(hand_ruled_out(spec("dh3/bus0/1"), kCell));
  EXPECT_FALSE(hand_ruled_out(spec("left"), kCell));
  EXPECT_FALSE(hand_ruled_out(spec("bus1/4"), kCell));
  EXPECT_FALSE(hand_ruled_out(spec("2"), kCell));
}

TEST(HandLookup, NothingIsRuledOutBeforeTheServiceHasSaidWhatItHas) {
  EXPECT_FALSE(hand_ruled_out(spec("dh3/bus0/9"), {}));
  EXPECT_FALSE(hand_ruled_out(spec("other/bus0/1"), kCell));
  EXPECT_FALSE(hand_ruled_out(spec("9"), {}));
}

TEST(HandLookup, ABusThatDiscoversItsHandsMayStillFindTheHand) {
  const std::vector<ServiceInfo> discovering{
      service("dh3", {bus("bus0", {{1, ""}}), bus("can0", {})})};
  EXPECT_FALSE(hand_ruled_out(spec("9"), discovering));
  EXPECT_FALSE(hand_ruled_out(spec("dh3/can0/9"), discovering));
  EXPECT_TRUE(hand_ruled_out(spec("dh3/bus0/9"), discovering));
}

}  // namespace
}  // namespace dh3::detail
