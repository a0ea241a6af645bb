// dds/client_share: each participant has at most its share of requests in
// flight; beyond it a request is refused with a message that says why, and a
// slot is free again when its request is answered.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "client_share.hpp"

namespace dh3::dds {
namespace {

using ::testing::HasSubstr;

TEST(ClientShare, AClientOverItsShareIsRefusedSayingHowManyAndTheBound) {
  ClientShare share(3);
  std::vector<ClientShare::Ticket> held;
  for (int i = 0; i < 3; ++i) {
    auto ticket = share.admit("aa01", "dh3ctl on cell-pc");
    ASSERT_TRUE(ticket) << "request " << i;
    held.push_back(std::move(ticket).value());
  }
  const auto refused = share.admit("aa01", "dh3ctl on cell-pc");
  ASSERT_FALSE(refused);
  EXPECT_THAT(refused.error(), HasSubstr("'dh3ctl on cell-pc' (participant aa01)"));
  EXPECT_THAT(refused.error(), HasSubstr("has 3 requests in flight; at most 3"));
  EXPECT_EQ(share.in_flight("aa01"), 3u);
}

TEST(ClientShare, OneClientsFloodLeavesAnotherClientItsWholeShare) {
  ClientShare share(2);
  std::vector<ClientShare::Ticket> held;
  for (int i = 0; i < 2; ++i) held.push_back(share.admit("flood", "flood").value());
  for (int i = 0; i < 100; ++i) EXPECT_FALSE(share.admit("flood", "flood"));
  auto first = share.admit("other", "other");
  auto second = share.admit("other", "other");
  EXPECT_TRUE(first);
  EXPECT_TRUE(second);
  EXPECT_EQ(share.in_flight("other"), 2u);
  EXPECT_EQ(share.refused(), 100u);  // for the metrics: only the flood's
}

TEST(ClientShare, ASlotIsFreeWhenTheLastCopyOfItsTicketIsGone) {
  ClientShare share(1);
  {
    auto ticket = share.admit("aa", "aa").value();
    // A completion may be copied on its way through a scheduler.
    const ClientShare::Ticket copy = ticket;
    ticket = {};
    EXPECT_FALSE(share.admit("aa", "aa")) << "a copy still holds the slot";
  }
  EXPECT_EQ(share.in_flight("aa"), 0u);
  EXPECT_TRUE(share.admit("aa", "aa"));
}

}  // namespace
}  // namespace dh3::dds
