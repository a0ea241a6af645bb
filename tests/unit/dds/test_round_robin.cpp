// dds/round_robin: a batch of requests is served one client at a time in
// turn, each client's own requests in the order they came.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "round_robin.hpp"

namespace dh3::dds {
namespace {

using ::testing::ElementsAre;

TEST(RoundRobin, AnotherClientsOneRequestBehindAFloodIsServedSecond) {
  std::vector<std::string> callers(100, "flood");
  callers.push_back("other");
  const auto order = round_robin_order(callers);
  ASSERT_EQ(order.size(), 101u);
  EXPECT_EQ(order[0], 0u);
  EXPECT_EQ(order[1], 100u);
  for (std::size_t i = 2; i < order.size(); ++i) EXPECT_EQ(order[i], i - 1);
}

TEST(RoundRobin, ClientsTakeTurnsInTheOrderTheyFirstCameAndKeepTheirOwnOrder) {
  EXPECT_THAT(round_robin_order({"a", "a", "b", "a", "c", "b"}), ElementsAre(0, 2, 4, 1, 5, 3));
  EXPECT_THAT(round_robin_order({}), ElementsAre());
  EXPECT_THAT(round_robin_order({"a", "b", "c"}), ElementsAre(0, 1, 2));
}

}  // namespace
}  // namespace dh3::dds
