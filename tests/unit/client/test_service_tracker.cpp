// ServiceTracker without DDS: which participant is a service's incarnation,
// when it is ready, and when a departure or a restart loses it.

#include <gtest/gtest.h>

#include "service_tracker.hpp"

namespace dh3::detail {
namespace {

using Endpoint = ServiceTracker::Endpoint;
using Outcome = ServiceTracker::Outcome;

ServiceInfo info_of(const std::string& service, std::uint64_t started_ns) {
  ServiceInfo info;
  info.name = service;
  info.started_ns = started_ns;
  // Appended, not "v" + ...: GCC 12 warns falsely (-Wrestrict) on that at -O3.
  info.version = std::to_string(started_ns);
  info.version.insert(0, 1, 'v');
  return info;
}

void match_commands(ServiceTracker& tracker, const std::string& prefix) {
  tracker.matched(Endpoint::request_reader, prefix, true);
  tracker.matched(Endpoint::reply_writer, prefix, true);
  tracker.matched(Endpoint::event_writer, prefix, true);
}

TEST(ServiceTracker, AServiceIsReadyOnceItsIncarnationMatchedAllThreeEndpoints) {
  ServiceTracker tracker;
  Outcome found;
  ASSERT_TRUE(tracker.note_participant("A", "svc", found));
  EXPECT_EQ(found.service, "svc");
  EXPECT_TRUE(found.may_dispatch);
  EXPECT_FALSE(found.lost_service);
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  EXPECT_FALSE(tracker.ready("svc"));
  tracker.matched(Endpoint::request_reader, "A", true);
  EXPECT_EQ(tracker.matched(Endpoint::reply_writer, "A", true), "svc");
  EXPECT_FALSE(tracker.ready("svc"));
  tracker.matched(Endpoint::event_writer, "A", true);
  EXPECT_TRUE(tracker.ready("svc"));
  EXPECT_FALSE(tracker.group_ready("svc"));
  tracker.matched(Endpoint::group_request_reader, "A", true);
  tracker.matched(Endpoint::group_reply_writer, "A", true);
  EXPECT_TRUE(tracker.group_ready("svc"));
  tracker.matched(Endpoint::reply_writer, "A", false);
  EXPECT_FALSE(tracker.ready("svc"));
}

TEST(ServiceTracker, AReadOnlyClientIsReadyWithTheEventWriterAlone) {
  ServiceTracker tracker;
  tracker.set_endpoints(false, false);
  Outcome found;
  tracker.note_participant("A", "svc", found);
  tracker.matched(Endpoint::event_writer, "A", true);
  EXPECT_TRUE(tracker.ready("svc"));
}

TEST(ServiceTracker, TheCurrentIncarnationLeavingLosesTheServiceAndAnotherTakesOver) {
  ServiceTracker tracker;
  Outcome ignored;
  tracker.take_info("A", info_of("svc", 100), ignored);
  tracker.note_participant("B", "svc", ignored);        // a second one, not current
  tracker.take_info("C", info_of("svc", 50), ignored);  // older: the current one stays
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  match_commands(tracker, "A");
  const Outcome left = tracker.participant_left("A");
  EXPECT_TRUE(left.lost_service);
  EXPECT_EQ(left.lost, "A");
  EXPECT_EQ(left.why, "service 'svc' left the domain");
  EXPECT_TRUE(left.may_dispatch);
  // C's info says when it started; B's does not.
  EXPECT_EQ(tracker.incarnation("svc"), "C");
  EXPECT_TRUE(tracker.alive("svc"));
  EXPECT_FALSE(tracker.ready("svc"));
  EXPECT_TRUE(tracker.participant_gone("A"));
  Outcome late;
  EXPECT_FALSE(tracker.note_participant("A", "svc", late));  // a late sample of the gone one
  EXPECT_FALSE(late.may_dispatch);
}

TEST(ServiceTracker, AParticipantThatWasNotCurrentLeavesWithoutALoss) {
  ServiceTracker tracker;
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored);
  tracker.note_participant("B", "svc", ignored);
  const Outcome left = tracker.participant_left("B");
  EXPECT_FALSE(left.lost_service);
  EXPECT_FALSE(left.may_dispatch);
  EXPECT_EQ(tracker.incarnation("svc"), "A");
}

TEST(ServiceTracker, ANewerStartedInstanceIsARestart) {
  ServiceTracker tracker;
  Outcome ignored;
  tracker.take_info("A", info_of("svc", 100), ignored);
  Outcome restart;
  ASSERT_TRUE(tracker.take_info("B", info_of("svc", 200), restart));
  EXPECT_TRUE(restart.lost_service);
  EXPECT_EQ(restart.lost, "A");
  EXPECT_EQ(restart.why, "service 'svc' restarted");
  EXPECT_TRUE(restart.may_dispatch);
  EXPECT_EQ(tracker.incarnation("svc"), "B");
  ASSERT_TRUE(tracker.service("svc"));
  EXPECT_EQ(tracker.service("svc")->version, "v200");
  // The old one's last info changes nothing.
  Outcome stale;
  EXPECT_FALSE(tracker.take_info("A", info_of("svc", 100), stale));
  EXPECT_FALSE(stale.lost_service);
  EXPECT_EQ(tracker.service("svc")->version, "v200");
}

TEST(ServiceTracker, FindReadyWaitsForTheInfoWhenAskedTo) {
  ServiceTracker tracker;
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored);
  match_commands(tracker, "A");
  EXPECT_FALSE(tracker.find_ready("svc", true));
  ASSERT_TRUE(tracker.find_ready("", false));
  EXPECT_TRUE(tracker.find_ready("", false)->ready);
  EXPECT_FALSE(tracker.find_ready("other", false));
  tracker.take_info("A", info_of("svc", 1), ignored);
  ASSERT_TRUE(tracker.find_ready("svc", true));
  EXPECT_EQ(tracker.find_ready("svc", true)->version, "v1");
  EXPECT_EQ(tracker.ready_services().size(), 1U);
  EXPECT_EQ(tracker.infos().size(), 1U);
}

TEST(ServiceTracker, AliveAndAnyAliveFollowTheIncarnations) {
  ServiceTracker tracker;
  EXPECT_FALSE(tracker.any_alive());
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored);
  EXPECT_TRUE(tracker.alive("svc"));
  EXPECT_TRUE(tracker.any_alive());
  tracker.participant_left("A");
  EXPECT_FALSE(tracker.alive("svc"));
  EXPECT_FALSE(tracker.any_alive());
  EXPECT_EQ(tracker.services().size(), 1U);  // still known, not alive
}

TEST(ServiceTracker, AParticipantDiscoveryDroppedAndFoundAgainServesOnceItMatchesAgain) {
  ServiceTracker tracker;
  Outcome ignored;
  ASSERT_TRUE(tracker.participant_found("A", "svc", ignored));
  match_commands(tracker, "A");
  ASSERT_TRUE(tracker.ready("svc"));
  tracker.participant_left("A");  // its lease ran out in a process that starved
  Outcome late;
  EXPECT_FALSE(tracker.note_participant("A", "svc", late)) << "a late status of the gone one";

  Outcome found;
  ASSERT_TRUE(tracker.participant_found("A", "svc", found));
  EXPECT_EQ(found.service, "svc");
  EXPECT_TRUE(found.may_dispatch);
  EXPECT_FALSE(tracker.participant_gone("A"));
  EXPECT_TRUE(tracker.alive("svc"));
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  EXPECT_FALSE(tracker.ready("svc")) << "its endpoints left with it";
  match_commands(tracker, "A");
  EXPECT_TRUE(tracker.ready("svc"));
}

TEST(ServiceTracker, SightingsSayWhatDiscoveryShowedOfAServiceThatIsNotAlive) {
  ServiceTracker tracker;
  EXPECT_EQ(tracker.sightings("svc"), "discovery found no participant announcing it");
  Outcome ignored;
  tracker.participant_found("A", "svc", ignored);
  tracker.participant_found("B", "other", ignored);
  EXPECT_EQ(tracker.sightings("svc"),
            "discovery found participant A: believed, its request reader, reply writer, group "
            "request reader, group reply writer, event writer not matched with this client");
  match_commands(tracker, "A");
  EXPECT_EQ(tracker.sightings("svc"),
            "discovery found participant A: believed, its group request reader, group reply "
            "writer not matched with this client");
  tracker.participant_left("A");
  EXPECT_EQ(tracker.sightings("svc"),
            "discovery found participant A: it left the domain or stopped asserting it lives");
}

}  // namespace
}  // namespace dh3::detail
