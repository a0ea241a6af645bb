// dh3/base/hand_ids.hpp: the one grammar of a list of hand IDs.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "dh3/base/hand_ids.hpp"

namespace dh3 {
namespace {

using ::testing::HasSubstr;
using Ids = std::vector<std::uint8_t>;

std::string error_of(std::string_view text) {
  auto parsed = parse_hand_ids(text);
  return parsed ? std::string("parsed") : parsed.error();
}

TEST(HandIds, ReadsIdsAndRangesInTheOrderGiven) {
  EXPECT_EQ(parse_hand_ids("1,2,3").value(), (Ids{1, 2, 3}));
  EXPECT_EQ(parse_hand_ids("255,7").value(), (Ids{255, 7}));
  EXPECT_EQ(parse_hand_ids("1-4,10").value(), (Ids{1, 2, 3, 4, 10}));
  EXPECT_EQ(parse_hand_ids("9,3-3").value(), (Ids{9, 3}));
  EXPECT_EQ(parse_hand_ids("1-255").value().size(), 255U);
}

TEST(HandIds, RefusesWhatNamesNoHandSayingWhich) {
  EXPECT_THAT(error_of(""), HasSubstr("no hand ids"));
  EXPECT_THAT(error_of("0"), HasSubstr("hand id 0 is not a hand's id"));
  EXPECT_THAT(error_of("0-3"), HasSubstr("hand id 0 is not a hand's id"));
  EXPECT_THAT(error_of("256"), HasSubstr("hand id 256 is out of range 1-255"));
  EXPECT_THAT(error_of("1-300"), HasSubstr("hand id 300 is out of range 1-255"));
  EXPECT_THAT(error_of("99999999999"), HasSubstr("out of range 1-255"));
  EXPECT_THAT(error_of("1,,2"), HasSubstr("hand id '' is not a number"));
  EXPECT_THAT(error_of("1,"), HasSubstr("hand id '' is not a number"));
  EXPECT_THAT(error_of("1,x"), HasSubstr("hand id 'x' is not a number"));
  EXPECT_THAT(error_of("-1"), HasSubstr("hand id '-1' is not a number"));
  EXPECT_THAT(error_of("1-"), HasSubstr("hand id '1-' is not a number"));
  EXPECT_THAT(error_of("1 "), HasSubstr("hand id '1 ' is not a number"));
  EXPECT_THAT(error_of("8-1"), HasSubstr("empty range 8-1"));
  EXPECT_THAT(error_of("1,2,1"), HasSubstr("hand id 1 is listed twice"));
  EXPECT_THAT(error_of("1-3,2"), HasSubstr("hand id 2 is listed twice"));
}

}  // namespace
}  // namespace dh3
