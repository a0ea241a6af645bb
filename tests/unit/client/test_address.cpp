// How users name hands: parsing the forms and resolving the short ones.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "dh3/address.hpp"

namespace dh3 {
namespace {

using ::testing::HasSubstr;

TEST(HandSpecTest, FullAddressParsesIntoItsParts) {
  const auto spec = parse_hand_spec("cell/bus0/2");
  ASSERT_TRUE(spec) << spec.message();
  EXPECT_TRUE(spec->is_full());
  EXPECT_EQ(spec->address(), (HandAddress{"cell", "bus0", 2}));
  EXPECT_EQ(spec->address().to_string(), "cell/bus0/2");
}

TEST(HandSpecTest, ShortFormsLeaveOutWhatTheyDoNotSay) {
  const auto bus_id = parse_hand_spec("bus0/7");
  ASSERT_TRUE(bus_id);
  EXPECT_FALSE(bus_id->service);
  EXPECT_EQ(bus_id->bus, "bus0");
  EXPECT_EQ(bus_id->can_id, 7);

  const auto service_name = parse_hand_spec("cell/left");
  ASSERT_TRUE(service_name);
  EXPECT_EQ(service_name->service, "cell");
  EXPECT_EQ(service_name->name, "left");
  EXPECT_FALSE(service_name->can_id);

  const auto id = parse_hand_spec("255");
  ASSERT_TRUE(id);
  EXPECT_EQ(id->can_id, 255);
  EXPECT_FALSE(id->is_full());

  const auto name = parse_hand_spec("left");
  ASSERT_TRUE(name);
  EXPECT_EQ(name->name, "left");
}

TEST(HandSpecTest, MalformedSpecsAreRefusedWithTheReason) {
  for (const char* text : {"", "a//1", "/bus0/1", "a/b/c/d", "cell/bus0/left", "cell/bus0/", "0",
                           "256", "cell/bus0/999"}) {
    const auto spec = parse_hand_spec(text);
    EXPECT_FALSE(spec) << text;
    EXPECT_EQ(spec.code(), Code::invalid_argument) << text;
    EXPECT_THAT(spec.message(), HasSubstr("bad hand")) << text;
  }
  EXPECT_THAT(parse_hand_spec("cell/bus0/300").message(), HasSubstr("out of range (1-255)"));
}

std::vector<KnownHand> two_services() {
  return {{{"cell", "bus0", 1}, "left"},
          {{"cell", "bus0", 2}, "right"},
          {{"lab", "bus0", 2}, ""},
          {{"lab", "can1", 3}, "spare"}};
}

TEST(ResolveHandTest, ShortFormsResolveWhenExactlyOneHandMatches) {
  const auto known = two_services();
  EXPECT_EQ(*resolve_hand(*parse_hand_spec("left"), known), (HandAddress{"cell", "bus0", 1}));
  EXPECT_EQ(*resolve_hand(*parse_hand_spec("3"), known), (HandAddress{"lab", "can1", 3}));
  EXPECT_EQ(*resolve_hand(*parse_hand_spec("can1/3"), known), (HandAddress{"lab", "can1", 3}));
  EXPECT_EQ(*resolve_hand(*parse_hand_spec("cell/right"), known), (HandAddress{"cell", "bus0", 2}));
}

TEST(ResolveHandTest, AmbiguousSpecListsTheCandidates) {
  const auto found = resolve_hand(*parse_hand_spec("2"), two_services());
  ASSERT_FALSE(found);
  EXPECT_EQ(found.code(), Code::invalid_argument);
  EXPECT_THAT(found.message(), HasSubstr("ambiguous"));
  EXPECT_THAT(found.message(), HasSubstr("cell/bus0/2"));
  EXPECT_THAT(found.message(), HasSubstr("lab/bus0/2"));
}

TEST(ResolveHandTest, NoMatchIsUnknownHandAndSaysWhatIsKnown) {
  const auto found = resolve_hand(*parse_hand_spec("middle"), two_services());
  ASSERT_FALSE(found);
  EXPECT_EQ(found.code(), Code::unknown_hand);
  EXPECT_THAT(found.message(), HasSubstr("cell/bus0/1 (left)"));
  EXPECT_THAT(resolve_hand(*parse_hand_spec("4"), {}).message(), HasSubstr("no hands known"));
}

TEST(ResolveHandTest, FullAddressNeedsNoKnownHand) {
  const auto found = resolve_hand(*parse_hand_spec("other/bus9/9"), two_services());
  ASSERT_TRUE(found);
  EXPECT_EQ(*found, (HandAddress{"other", "bus9", 9}));
}

TEST(ResolveHandTest, TheSameHandKnownTwiceIsNotAmbiguous) {
  auto known = two_services();
  known.push_back({{"cell", "bus0", 1}, "left"});
  EXPECT_TRUE(resolve_hand(*parse_hand_spec("left"), known));
}

}  // namespace
}  // namespace dh3
