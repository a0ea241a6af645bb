// The link as the bus loop sees it: down when an operation fails with
// link_down, up again when the bus says so; each change reported once.

#include <gtest/gtest.h>

#include "link_monitor.hpp"

namespace dh3::hand {
namespace {

using bus::LinkState;

TEST(LinkMonitor, StartsAsTheBusWas) {
  const LinkMonitor up(LinkState::up);
  EXPECT_TRUE(up.up());
  EXPECT_EQ(up.state(), LinkState::up);
  const LinkMonitor down(LinkState::down);
  EXPECT_FALSE(down.up());
  EXPECT_EQ(down.state(), LinkState::down);
  EXPECT_EQ(down.reconnects(), 0u);
}

TEST(LinkMonitor, ALostLinkIsReportedOnce) {
  LinkMonitor link(LinkState::up);
  EXPECT_EQ(link.on_link_lost(), LinkChange::went_down);
  EXPECT_FALSE(link.up());
  EXPECT_EQ(link.state(), LinkState::down);
  // The receive and the sends of the same pass may all fail with it.
  EXPECT_EQ(link.on_link_lost(), LinkChange::none);
  EXPECT_EQ(link.on_reported(LinkState::down), LinkChange::none);
  EXPECT_EQ(link.reconnects(), 0u);
}

TEST(LinkMonitor, AReportedDownIsBelievedOnlyWhenAnOperationFails) {
  LinkMonitor link(LinkState::up);
  EXPECT_EQ(link.on_reported(LinkState::down), LinkChange::none);
  EXPECT_TRUE(link.up());
  EXPECT_EQ(link.state(), LinkState::up);
}

TEST(LinkMonitor, TheLinkComesBackWhenTheBusSaysSoAndCountsAReconnect) {
  LinkMonitor link(LinkState::up);
  ASSERT_EQ(link.on_link_lost(), LinkChange::went_down);
  EXPECT_EQ(link.on_reported(LinkState::up), LinkChange::came_up);
  EXPECT_TRUE(link.up());
  EXPECT_EQ(link.state(), LinkState::up);
  EXPECT_EQ(link.on_reported(LinkState::up), LinkChange::none);
  ASSERT_EQ(link.on_link_lost(), LinkChange::went_down);
  ASSERT_EQ(link.on_reported(LinkState::up), LinkChange::came_up);
  EXPECT_EQ(link.reconnects(), 2u);
}

TEST(LinkMonitor, ABusThatStartedDownCountsItsFirstUpAsAReconnect) {
  LinkMonitor link(LinkState::down);
  EXPECT_EQ(link.on_link_lost(), LinkChange::none);
  EXPECT_EQ(link.on_reported(LinkState::up), LinkChange::came_up);
  EXPECT_EQ(link.reconnects(), 1u);
}

}  // namespace
}  // namespace dh3::hand
